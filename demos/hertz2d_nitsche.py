# # Hertz line contact with Nitsche's method
#
# A rigid cylinder of radius $R$ is pressed into an elastic plane-strain block; the contact
# pressure is compared with Hertz's closed form at the computed force.
#
# It illustrates how to:
# - set up a scene from Python and choose the enforcement method,
# - read the contact force, half-width and peak pressure from the result,
# - run the same script serially and with `mpirun -n 2`.
#
# ## Problem
#
# Find $u$ with $-\mathrm{div}\,\sigma(u) = 0$ in the block, $u = 0$ at the bottom, and on the
# top surface the Signorini conditions $g(u) \ge 0$, $p \ge 0$, $g p = 0$ with the gap
# $g(u) = x^2 / (2R) - (u_y + \delta)$ for the indentation depth $\delta$. Nitsche's method
# writes them as $p = [-\sigma_n(u) - \gamma_N g(u)]_+$ with $\gamma_N = \gamma_0 E / h$ and
# adds $\int (1/\gamma_N) p\, (\gamma_N v_n - \theta \sigma_n(v))
# - (\theta/\gamma_N) \sigma_n(u) \sigma_n(v)\, ds$ to the elastic residual.
#
# Hertz: $a = \sqrt{4 P R / (\pi E^*)}$, $p_0 = 2 P / (\pi a)$ with $E^* = E / (1 - \nu^2)$.
#
# ## Data
#
# $R = 1$, $E = 1000$, $\nu = 0.3$, block $2 \times 1$, $\delta = 1.5 \cdot 10^{-3}$ (a/R about
# 0.026), element size $3 \cdot 10^{-3}$ in the contact zone.

# +
from mpi4py import MPI

from contactfx.scenes import Numerics
from contactfx.scenes.hertz import Hertz2D, Hertz2DParams

scene = Hertz2D(Hertz2DParams(radius=1.0, depth=1.5e-3, E=1000.0, nu=0.3))
# -

# The symmetric variant (theta = 1) with gamma0 = 10; the skew-symmetric one (theta = -1) is
# robust for any gamma0 > 0.

# +
result = scene.run(Numerics(method="nitsche", theta=1, gamma0=10.0), verbose=False)
ref = result["reference"]
# -

# The number to check: it agrees between serial and parallel runs.

# +
if MPI.COMM_WORLD.rank == 0:
    print(f"force P = {result['force']:.8f}")
    print(f"a  = {ref['a_computed']:.6f} (Hertz {ref['a']:.6f}, {ref['a_error_over_h']:.2f} h)")
    print(f"p0 = {ref['p0_computed']:.4f} (Hertz {ref['p0']:.4f}, {ref['p0_rel_error']:.2%})")
# -
