"""Wrinkle Studio: author and preview real-time facial expression wrinkles."""

__version__ = "0.1.0"
