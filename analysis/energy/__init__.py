"""Where the energy goes: the per-slip partition of the spring's energy
(:mod:`.partition`), the check of the film's heat against the thermostat's
(:mod:`.heat_check`) and the whole run's ledger (:mod:`.ledger`)."""
