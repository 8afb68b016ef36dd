"""The model at the scale of Klein's surface-force-balance experiment.

* :mod:`~filmfriction.reduced_model.sfb.klein` — Klein's experiment and his slip equation;
* :mod:`~filmfriction.reduced_model.sfb.check` — the SFB check (:func:`sfb_check`) and its table;
* :mod:`~filmfriction.reduced_model.sfb.user_setup` — a user's own SFB set-up and measured slip;
* :mod:`~filmfriction.reduced_model.sfb.similarity` — the dimensionless numbers MD vs SFB;
* :mod:`~filmfriction.reduced_model.sfb.md_calibration` — the film as the MD measured it;
* :mod:`~filmfriction.reduced_model.sfb.md_rows` — the table's rows from the MD film;
* :mod:`~filmfriction.reduced_model.sfb.rows` — the table's row format;
* :mod:`~filmfriction.reduced_model.sfb.slip` — one slip of the spring block;
* :mod:`~filmfriction.reduced_model.sfb.heating` — the film's temperature rise in a slip.
"""
