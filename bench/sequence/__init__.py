"""One refinement sequence: solve -> estimate -> mark -> refine, a result row per level
(``ResultRow``, whose column names are a public interface)."""
