"""The performance study of the thesis (SPEC §7), reproduced and extended: ``wrinkle-studio bench``."""
