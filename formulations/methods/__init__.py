"""The formulations of Signorini's problem (docs/theory.md, sections 3 and 12): one module
each, registered on import (``register_formulation``)."""

from formulations.methods import mixed, nitsche, penalty, vi  # noqa: F401  (register themselves)
