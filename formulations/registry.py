"""Formulation registry: name -> ``discretise(scene, mesh) -> Discretisation``."""

from scenes.registry import Registry

FORMULATIONS = Registry("formulation")
register_formulation = FORMULATIONS.register
formulation_names = FORMULATIONS.names
formulation_descriptions = FORMULATIONS.descriptions
get_formulation = FORMULATIONS.get
