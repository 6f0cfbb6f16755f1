"""The thesis's performance study (SPEC §7), reproduced and extended: ``wrinkle-studio bench``."""
