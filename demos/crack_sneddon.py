# # A pressurised crack (Sneddon) and the same crack closed by suction
#
# A straight crack $|x| < a$ in a plane-strain plate is loaded by a fluid pressure $p$ on its
# faces. The crack is a chain of interior mesh facets; the displacement may jump across them
# (Heaviside enrichment) and the faces must not interpenetrate (Signorini, Nitsche's method
# on the jump).
#
# It illustrates how to:
# - run a fitted-interface scene from Python,
# - read the opening error, K_I and the contact force,
# - write the XDMF file (the discontinuous displacement opens the crack in ParaView's Warp By
#   Vector) and the line plot along the crack (`interface.png`, `interface.csv`).
#
# ## Problem
#
# Sneddon: $[[u_n]](x) = 4 p (1 - \nu^2) / E \sqrt{a^2 - x^2}$, $K_I = p \sqrt{\pi a}$. The plate's
# boundary carries the traction of the infinite plate's Westergaard field, so the only error
# is the discretisation's. With $p < 0$ the faces close and carry the uniform pressure $-p$:
# the contact force is $2 a |p|$ and nothing else moves.
#
# ## Data
#
# $E = 10$ GPa, $\nu = 0.25$, $a = 1$ m, plate $20 \times 20$ m, $p = \pm 1$ MPa; element size
# $a/40$ along the crack, $a/400$ at the tips.

# +
from mpi4py import MPI

from contactfx.scenes.crack import CrackSneddon

open_crack = CrackSneddon(CrackSneddon.Params(pressure=1e6))
result = open_crack.run(open_crack.default_numerics(method="nitsche"), out="out/crack-sneddon",
                        verbose=False)  # fmt: skip
closed = CrackSneddon(CrackSneddon.Params(pressure=-1e6))
suction = closed.run(closed.default_numerics(method="nitsche"), verbose=False)
# -

# +
if MPI.COMM_WORLD.rank == 0:
    ref = result["reference"]
    print(f"opening L2 error  {result['errors']['opening_L2_rel']:.4e}")
    print(f"K_I / (p sqrt(pi a)) = {ref['K_I'] / ref['K_I_exact']:.4f}")
    print(f"contact force (p > 0): {result['normal_force']:.1f}  (no false contact)")
    print(f"contact force (p < 0): {suction['normal_force']:.4e}  (2 a |p| = 2.0000e+06)")
# -
