"""What a discrete solution is measured by: its contact zone, its difference to another
solution of the same discrete problem, and its discretisation error against an exact solution or
a reference on another mesh (docs/theory.md, section 6). Depends on ``formulations`` only."""
