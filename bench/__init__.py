"""bench: matrix harness, refinement loop, marking, result store and CLI (``python -m bench``)."""
