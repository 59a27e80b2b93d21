"""The seed problems and demos, each runnable end to end on embedded data."""
