# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
#       format_version: '1.5'
# ---

# # A pressurised crack (Sneddon), and the same crack closed by suction
#
# This demo loads a straight crack in a plane-strain plate by a fluid pressure on its faces,
# keeps the faces from interpenetrating by Nitsche's method on the displacement jump, and
# compares the opening and the stress intensity factor with Sneddon's closed form.
#
# It illustrates how to:
#
# - run a fitted-interface scene: the crack is a chain of interior mesh facets across which the
#   displacement may jump,
# - write Nitsche's contact residual on the crack faces (jumps and averages) and check that it
#   is the one the run assembles,
# - read the opening error, $K_I$ and the contact force from the typed run summary,
# - write the ParaView files and the line plot along the crack.
#
# ## Equations
#
# The plate $\Omega = (-W/2, W/2)^2$ contains the crack $\Gamma = \{|x| < a, y = 0\}$ with the
# unit normal $n_I = e_y$; $[\![w]\!] = w^+ - w^-$ is the jump across $\Gamma$ (from the side
# $n_I$ points away from to the side it points to), $\{\cdot\}$ the average of the two sides,
# $\sigma_n = n_I \cdot \sigma n_I$. Find the displacement $w$ with
#
# $$
# \begin{aligned}
# -\nabla \cdot \sigma(w) &= 0 \quad \text{in } \Omega \setminus \Gamma, \qquad
# \sigma(w) n = \sigma^\infty n \quad \text{on } \partial \Omega, \\
# \sigma(w) n_I &= -(p_f + P) n_I \quad \text{on both faces}, \qquad
# g = [\![w]\!] \cdot n_I \ge 0, \quad P \ge 0, \quad P g = 0,
# \end{aligned}
# $$
#
# where $p_f$ is the fluid pressure, $P$ the contact pressure between the faces and
# $\sigma^\infty$ the stress of the same crack in an infinite plate (docs/verification.md
# section 6), so that the only error is the discretisation's. The contact law acts on the
# effective normal stress: $P = -(\sigma_n(w) + p_f)$.
#
# The displacement is $w = u + H a$ with $u$, $a$ continuous P1 fields, $H = \pm 1$ on the two
# sides, and $a$ nonzero only at the nodes of $\Gamma$ and zero at the tips, so that
# $[\![w]\!] = 2 a$ on $\Gamma$ (Heaviside enrichment on a fitted crack: Moes, Dolbow &
# Belytschko 1999, doi:10.1002/(SICI)1097-0207(19990910)46:1<131::AID-NME726>3.0.CO;2-J).
# Nitsche's method with the averaged stress (Chouly, Fabre, Hild, Pousin & Renard 2018,
# doi:10.1051/m2an/2017056; Annavarapu, Hautefeuille & Dolbow 2014,
# doi:10.1016/j.cma.2013.09.025) sets
# $P_\gamma(w) = [-(\{\sigma_n(w)\} + p_f) - \gamma [\![w]\!] \cdot n_I]_+$,
# $\gamma = \gamma_0 E / \{h\}$, and the weak form is: for all $v$,
#
# $$
# \begin{aligned}
# \int_{\Omega \setminus \Gamma} \sigma(w) : \varepsilon(v) \, \mathrm{d}x
# &- \int_{\partial \Omega} \sigma^\infty n \cdot v \, \mathrm{d}s
# - \int_\Gamma p_f [\![v]\!] \cdot n_I \, \mathrm{d}S \\
# &- \int_\Gamma P_\gamma(w) \left( [\![v]\!] \cdot n_I + \frac{\theta}{\gamma}
# \{\sigma_n(v)\} \right) \mathrm{d}S
# - \int_\Gamma \frac{\theta}{\gamma} (\{\sigma_n(w)\} + p_f) \{\sigma_n(v)\} \, \mathrm{d}S = 0.
# \end{aligned}
# $$
#
# It is the residual of `hertz2d_nitsche.py` with the upper face as the body, its outward
# normal $n = -n_I$ and the opening as the gap.
#
# Sneddon (1946, doi:10.1098/rspa.1946.0077): $[\![w]\!] \cdot n_I = 4 p_f (1 - \nu^2) / E
# \sqrt{a^2 - x^2}$ and $K_I = p_f \sqrt{\pi a}$, estimated from the jump near the tips by
# displacement extrapolation on $a/20 \le r \le a/2$ (Chan, Tuba & Wilson 1970,
# doi:10.1016/0013-7944(70)90026-3). With $p_f < 0$ (suction) the faces close and carry the
# uniform contact pressure $P = -p_f$, the contact force is $2 a |p_f|$ and the plate stays
# unstressed.
#
# ## Data
#
# $E = 10$ GPa, $\nu = 0.25$, $a = 1$ m, $W = 20$ m, $p_f = \pm 1$ MPa; element size $a/40$
# along the crack, $a/400$ at the tips, $0.5$ m far away; $\theta = 1$, $\gamma_0 = 10$; one
# load step.
#
# ## Implementation

# +
import ufl
from mpi4py import MPI

from contactfx.driver import setup
from contactfx.scenes.crack import CrackSneddon
from contactfx.validation.residual import random_state, relative_difference

pressurised = CrackSneddon(CrackSneddon.Params(pressure=1e6))
num = pressurised.default_numerics(method="nitsche", theta=1, gamma0=10.0)
method = num.method_object()
# -

# On the crack the contact surface `s` (`contactfx.contact.interface.InterfaceSurface`) offers
# the members of the obstacle's surface: `s.u` $= [\![w]\!]$, `s.v` $= [\![v]\!]$, `s.stress`
# $= \{\sigma(w)\} + p_f I$, `s.stress_test` $= \{\sigma(v)\}$, `s.h` $= \{h\}$, `s.ds` the
# interior-facet measure of $\Gamma$, and `s.interface_normal()` $= n_I$. The contact terms of
# the weak form:


# +
def crack_nitsche_residual(s, theta, gamma0):
    n_I = s.interface_normal()
    gamma = gamma0 * s.E / s.h
    sigma_n_w = ufl.dot(n_I, ufl.dot(s.stress, n_I))  # {sigma_n(w)} + p_f
    sigma_n_v = ufl.dot(n_I, ufl.dot(s.stress_test, n_I))
    P = ufl.max_value(-sigma_n_w - gamma * ufl.dot(s.u, n_I), 0.0)
    return (
        -P * (ufl.dot(s.v, n_I) + theta / gamma * sigma_n_v) - theta / gamma * sigma_n_w * sigma_n_v
    ) * s.ds


# -

# The check that it is what the run assembles: build the problem `scene.run` solves (`setup`), apply
# the fluid pressure, take an arbitrary state (random nodal values of $u$ and $a$) and compare the
# assembled vectors.


# +
problem = setup(pressurised, num)
problem.apply_load(1.0)
random_state(problem.state, 1e-4)
s = problem.surface
F_run = method.residual(s)
mismatch = relative_difference(F_run, crack_nitsche_residual(s, num.theta, num.gamma0))
assert mismatch < 1e-12, mismatch  # the run assembles exactly this residual
# -

# Solve the pressurised crack, writing the ParaView files (`crack-sneddon.pvd`: the crack faces
# as separate nodes, `displacement` $u \pm a$ on each face, so that Warp By Vector opens the
# crack; `crack-sneddon_surface.pvd`: the crack line), `interface.png`, `interface.csv` and
# `run.json` into `out/crack-sneddon`; then the crack under suction.

# +
res = pressurised.run(num, verbose=False, out="out/crack-sneddon")
closed = CrackSneddon(CrackSneddon.Params(pressure=-1e6))
suction = closed.run(closed.default_numerics(method="nitsche", theta=1, gamma0=10.0), verbose=False)
# -

# The numbers to check: they agree between serial and parallel runs.

# +
if MPI.COMM_WORLD.rank == 0:
    ref = res.reference
    print(f"method.residual vs the formula: relative difference {mismatch:.1e}")
    print(f"opening L2 error {res.errors['opening_L2_rel']:.4e}")
    print(f"K_I / (p sqrt(pi a)) = {ref['K_I'] / ref['K_I_exact']:.4f}")
    print(f"p > 0: contact force {res.force:.1f}, closed length {res.contact_size:.1f}")
    print(
        f"p < 0: contact force {suction.force:.4e} (2 a |p| = 2.0000e+06), relative error "
        f"{suction.reference['force_rel_error']:.1e}, opening L2 {suction.errors['opening_L2']:.1e}"
    )
    print(f"wrote {res.paraview} and {res.plot}")
# -
