"""The replicas of one scene run as a study, and the target error that stops it."""
