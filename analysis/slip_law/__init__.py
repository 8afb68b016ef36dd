"""The slip law: the film force of each slip against its velocity, fitted per branch and as
one law, and the verdict with its power (slip_law; its statistics, branch fits and rule)."""
