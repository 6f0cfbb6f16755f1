"""The thesis's performance study, reproduced and extended: ``wrinkle-studio bench``."""
