"""Performance measurements: the scaling table (``python -m bench scaling``)."""
