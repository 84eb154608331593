"""``residual-volume``: the residual eta_0 alone, without the contact terms of the seed's
eq. (8), to show what those terms add."""

from estimators import register_estimator
from estimators.base import Estimate
from estimators.residual.triangles import edge_residuals, element_residual


@register_estimator("residual-volume", "example plugin: the residual eta_0 alone (no contact "
                                       "terms of eq. (8))")
def estimate(scene, solution) -> Estimate:
    young = float(scene.material.young_modulus)
    local = (element_residual(scene, solution) + edge_residuals(scene, solution)) / young
    eta_0 = float(local.sum() ** 0.5)
    return Estimate("residual-volume", eta=eta_0, eta_0=eta_0, eta_geometric=0.0,
                    eta_complementarity=0.0, indicators=local)
