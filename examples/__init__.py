"""Runnable examples built on the framework (``python -m examples.platformer``)."""
