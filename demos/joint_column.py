# # The Barton-Bandis joint column
#
# Two rock blocks stacked on rollers, a joint between them (initial aperture $w_0$), the
# compression $s_c$ on top and the fluid pressure $p$ in the joint. The joint closes by
# $v = s' V_m / (K_{ni} V_m + s')$ under the effective stress $s' = s_c - p$ (Barton-Bandis), and
# the top settles by $2 H s_c / M + v$. The solution is uniform in each block: every mesh and
# every method reproduces the table of docs/verification.md section 7.
#
# It illustrates how to:
# - run the joint law with Nitsche's method and the augmented Lagrangian,
# - read the closure, aperture and settlement against the closed form.

# +
from mpi4py import MPI

from contactfx.scenes.joint import JointColumn

results = []
for s_c, p in ((30e6, 10e6), (30e6, 0.0), (60e6, 10e6)):
    scene = JointColumn(JointColumn.Params(closure_stress=s_c, fluid_pressure=p))
    for method in ("nitsche", "al-uzawa"):
        data = scene.run(scene.default_numerics(method=method), verbose=False,
                         out="out/joint-column").data  # fmt: skip
        results.append((s_c, p, method, data["reference"]))
# -

# +
if MPI.COMM_WORLD.rank == 0:
    for s_c, p, method, ref in results:
        print(
            f"s_c {s_c / 1e6:4.0f} MPa p {p / 1e6:4.0f} MPa {method:8s} closure "
            f"{ref['closure'] * 1e6:.3f} um aperture {ref['aperture'] * 1e6:.3f} um "
            f"settlement {ref['settlement'] * 1e3:.6f} mm"
        )
# -
