"""Friction (docs/theory.md, section 17): each formulation's friction companion (``nodal``
for vi, ``mixed``, ``slack`` shared by ``penalty`` and ``nitsche``) and the friction state of
a solution (``state``)."""
