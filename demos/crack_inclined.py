# # An inclined crack under compression with Coulomb friction: K_II
#
# A closed crack at the angle $\beta$ to the plane normal to a uniaxial compression $\sigma$
# carries $\sigma_n = \sigma \cos^2\beta$ and $\tau = \sigma \sin\beta \cos\beta$. With Coulomb
# friction $\mu$ the faces stick while $|\tau| \le \mu \sigma_n$; otherwise the whole crack
# slides with the face shear $\mu \sigma_n$, and
# $K_{II} = \sigma \sqrt{\pi a} \cos\beta (\sin\beta - \mu \cos\beta)$.
#
# It illustrates how to:
# - choose the friction coefficient and the method (Nitsche or augmented Lagrangian),
# - read K_II (displacement extrapolation of the slip near the tips) and the stick/slip status.
#
# ## Data
#
# $\sigma = 10$ MPa, $a = 1$, $\beta = 45$ degrees, $\mu = 0.3$ (sliding) and $\beta = 30$,
# $\mu = 0.6$ (stick).

# +
from mpi4py import MPI

from contactfx.scenes.crack import CrackInclined

sliding = CrackInclined(CrackInclined.Params(beta=45.0))
slide = sliding.run(sliding.default_numerics(method="al-ssn", mu=0.3), out="out/crack-inclined",
                    verbose=False)  # fmt: skip
sticking = CrackInclined(CrackInclined.Params(beta=30.0))
stick = sticking.run(sticking.default_numerics(method="nitsche", mu=0.6), verbose=False)
# -

# +
if MPI.COMM_WORLD.rank == 0:
    ref = slide["reference"]
    print(f"K_II / (sigma sqrt(pi a)) = {ref['K_II_normalised']:.4f}  (closed form 0.3500)")
    print(f"slipping fraction of the crack: {ref['slipping_fraction']:.3f}")
    print(f"stick case: max slip {stick['reference']['max_slip']:.3e}")
# -
