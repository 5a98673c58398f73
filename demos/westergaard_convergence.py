# # Westergaard's wavy surface: convergence of Nitsche's method in full contact
#
# A rigid sinusoid $z = \Delta (1 - \cos(2 \pi x / \lambda))$ is pressed on an elastic
# half-plane with the mean pressure $p_m$. Above $p^* = \pi E^* \Delta / \lambda$ the contact
# is complete and the displacement is smooth and known in closed form, so P1 elements must
# converge at the optimal rates: $O(h)$ in $H^1$ and $O(h^2)$ in $L^2$.
#
# It illustrates how to:
# - drive a scene by force (a traction on the bottom of the strip),
# - measure errors against an exact displacement field,
# - estimate observed convergence rates.
#
# ## Data
#
# $\lambda = 1$, $\Delta = 0.01$, $E = 1000$, $\nu = 0.3$, $p_m = 1.5 p^*$; half period
# $[0, \lambda/2] \times [-2\lambda, 0]$ with rollers on the sides.

# +
import numpy as np
from mpi4py import MPI

from contactfx.scenes import Numerics
from contactfx.scenes.westergaard import Westergaard, WestergaardParams

sizes = [1 / 8, 1 / 16, 1 / 32]
errors = []
for h in sizes:
    params = WestergaardParams(mean_pressure_ratio=1.5, h_contact=h, h_far=h)
    result = Westergaard(params).run(Numerics(method="nitsche", theta=-1), verbose=False)
    errors.append((result["errors"]["displacement_L2"], result["errors"]["displacement_H1"]))
errors = np.array(errors)
# -

# Observed rates between consecutive meshes:

# +
rates = np.log(errors[:-1] / errors[1:]) / np.log(2.0)
if MPI.COMM_WORLD.rank == 0:
    for h, (l2, h1) in zip(sizes, errors, strict=True):
        print(f"h = {h:.5f}  L2 = {l2:.4e}  H1 = {h1:.4e}")
    print("rates L2:", np.round(rates[:, 0], 2), " H1:", np.round(rates[:, 1], 2))
# -
