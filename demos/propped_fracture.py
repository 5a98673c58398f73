# # A fracture held open by a proppant layer
#
# A fracture $|x| < a$ under the closure stress $s_c$ and the fluid pressure $p$, with a rigid
# proppant layer of thickness $h$ on $|x| < b$: the aperture cannot drop below $h$ there. For the
# net pressure $p_{net} = p - s_c \ge p^* = h E' / (4 \sqrt{a^2 - b^2})$ the fracture is open
# (Sneddon) and the proppant carries nothing; below $p^*$ the proppant and then the faces carry
# the load.
#
# It illustrates how to:
# - set the proppant layer and the net pressure,
# - read the force on the proppant and the smallest aperture on the propped part.
#
# ## Data
#
# $E = 10$ GPa, $\nu = 0.25$, $a = 1$, $b = 0.5$, $h = 0.1$ mm ($p^* = 0.308$ MPa),
# $s_c = 20$ MPa, $p_{net} = 1$ MPa and $-1$ MPa.

# +
from mpi4py import MPI

from contactfx.scenes.crack import ProppedFracture

rows = []
for p_net in (1e6, -1e6):
    scene = ProppedFracture(ProppedFracture.Params(net_pressure=p_net))
    data = scene.run(scene.default_numerics(method="al-ssn"), verbose=False,
                     out=f"out/propped-fracture-{p_net:+.0e}").data  # fmt: skip
    rows.append((p_net, scene.p_star(), data))
# -

# +
if MPI.COMM_WORLD.rank == 0:
    for p_net, p_star, data in rows:
        ref = data["reference"]
        print(
            f"p_net {p_net:+.3e} (p* {p_star:.4e}): proppant force {data['proppant_force']:.4e}"
            f", min aperture / h {ref['min_aperture_propped_over_h']:.6f}"
        )
# -
