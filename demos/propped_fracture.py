# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
#       format_version: '1.5'
# ---

# # A fracture held open by a proppant layer
#
# This demo loads a fracture by a closure stress and a fluid pressure while a rigid proppant
# layer keeps its middle part from closing below the layer's thickness, with the contact
# conditions solved by the augmented Lagrangian method and semi-smooth Newton.
#
# It illustrates how to:
#
# - set the proppant layer and the net pressure of a fracture scene,
# - write the augmented Lagrangian residual (a multiplier field and a nodal complementarity
#   function) and check that it is the one the run assembles,
# - read the force on the proppant and the smallest propped aperture from the typed summary.
#
# ## Equations
#
# The fracture $\Gamma = \{|x| < a, y = 0\}$ (unit normal $n_I = e_y$) lies in the plate
# $\Omega = (-W/2, W/2)^2$ under the remote compression $s_c$ normal to it; the fluid in the
# fracture has the pressure $p_f = s_c + p_{net}$, and a rigid proppant layer of thickness
# $h_p$ lies on $|x| < b$. With the jump $[\![w]\!]$ across $\Gamma$, the aperture
# $[\![w]\!] \cdot n_I$ must stay above the layer: the gap is
# $g(w) = [\![w]\!] \cdot n_I - h_p(x)$, $h_p(x) = h_p$ on $|x| < b$ and $0$ elsewhere. Find $w$
# and the contact pressure $\lambda$ (of the proppant, or of the other face) with
#
# $$
# \begin{aligned}
# -\nabla \cdot \sigma(w) &= 0 \quad \text{in } \Omega \setminus \Gamma, \qquad
# \sigma(w) n = \sigma^\infty n \quad \text{on } \partial \Omega, \\
# \sigma(w) n_I &= -(p_f + \lambda) n_I \quad \text{on both faces}, \qquad
# g(w) \ge 0, \quad \lambda \ge 0, \quad \lambda g(w) = 0.
# \end{aligned}
# $$
#
# with $\sigma^\infty$ the stress of the infinite plate: the remote compression and, when the
# fracture is open, the field of its faces' net pressure (docs/verification.md section 6).
# The complementarity conditions are, for any $r > 0$, the equation
# $\lambda = [\lambda - r g(w)]_+$ (Alart & Curnier 1991, doi:10.1016/0045-7825(91)90022-X).
# The method `al-ssn` takes $\lambda$ as a P1 field on $\Gamma$, solved with
# $w$ by semi-smooth Newton (Hueeber & Wohlmuth 2005, doi:10.1016/j.cma.2004.09.012), and
# collocates that equation at the nodes (vertex quadrature, $\mathrm{d}S_\text{nodal}$), with
# $r = r_0 E / \{h\}$: for all $(v, \mu)$
#
# $$
# \begin{aligned}
# \int_{\Omega \setminus \Gamma} \sigma(w) : \varepsilon(v) \, \mathrm{d}x
# - \int_{\partial \Omega} \sigma^\infty n \cdot v \, \mathrm{d}s
# - \int_\Gamma p_f [\![v]\!] \cdot n_I \, \mathrm{d}S
# - \int_\Gamma \lambda [\![v]\!] \cdot n_I \, \mathrm{d}S &= 0, \\
# \int_\Gamma \left( \lambda - [\lambda - r g(w)]_+ \right) \mu \, \mathrm{d}S_\text{nodal}
# &= 0.
# \end{aligned}
# $$
#
# At a tip the gap vanishes identically and the second equation cannot fix $\lambda$: there it
# is replaced by $\lambda(\text{tip}) = \lambda(\text{neighbour})$ (`s.collocated`,
# docs/verification.md section 6).
#
# The layer is first touched at $x = \pm b$ when the net pressure drops to
# $p^* = h_p E' / (4 \sqrt{a^2 - b^2})$, $E' = E / (1 - \nu^2)$ (docs/verification.md section
# 7). For $p_{net} \ge p^*$ the fracture is open, its aperture is Sneddon's under $p_{net}$
# (Sneddon 1946, doi:10.1098/rspa.1946.0077), $K_I = p_{net} \sqrt{\pi a}$, and the proppant
# carries nothing. Below $p^*$ the proppant and then the faces beyond it carry the load: the
# proppant carries more than $2 b |p_{net}|$, and the aperture on it is exactly $h_p$ at the
# nodes that touch.
#
# ## Data
#
# $E = 10$ GPa, $\nu = 0.25$, $a = 1$ m, $W = 20$ m, $b = 0.5$ m, $h_p = 0.1$ mm
# ($p^* = 0.308$ MPa), $s_c = 20$ MPa, $p_{net} = 1$ MPa and $-1$ MPa; element size $a/40$ along
# the fracture, $a/400$ at the tips; $r_0 = 10$; one load step.
#
# ## Implementation

# +
import ufl
from mpi4py import MPI

from contactfx.driver import setup
from contactfx.scenes.crack import ProppedFracture
from contactfx.validation.residual import random_state, relative_difference


def fracture(p_net):
    params = ProppedFracture.Params(
        net_pressure=p_net,
        closure_stress=20e6,
        proppant_half_length=0.5,
        proppant_thickness=1e-4,
    )
    return ProppedFracture(params)


closing = fracture(-1e6)
num = closing.default_numerics(method="al-ssn", r0=10.0)
method = num.method_object()  # AugmentedLagrangianSSN(r0=10.0, ncp='min')
# -

# The contact terms on the fracture's surface `s`: `s.u` $= [\![w]\!]$, `s.v` $= [\![v]\!]$,
# `s.interface_normal()` $= n_I$, `s.floor` $= h_p(x)$, `s.multiplier` $= \lambda$ and
# `s.multiplier_test` $= \mu$ (on the upper face), `s.h` $= \{h\}$, and the measures `s.ds`
# ($\mathrm{d}S$ on $\Gamma$) and `s.ds_nodal` (its vertex rule).


# +
def al_ssn_residual(s, r0):
    n_I = s.interface_normal()
    r = r0 * s.E / s.h
    g = ufl.dot(s.u, n_I) - s.floor
    lam, mu = s.multiplier, s.multiplier_test
    C = s.collocated(lam - ufl.max_value(lam - r * g, 0.0))  # tied at the tips
    return -lam * ufl.dot(s.v, n_I) * s.ds + C * mu * s.ds_nodal


# -

# The check that it is what the run assembles: build the problem `scene.run` solves (`setup`), take
# an arbitrary state (random nodal values of the displacement and the multiplier) and compare the
# assembled vectors.


# +
problem = setup(closing, num)
problem.apply_load(1.0)
random_state(problem.state, 1e-4)
s = problem.surface
F_run = method.residual(s)
mismatch = relative_difference(F_run, al_ssn_residual(s, num.r0))
assert mismatch < 1e-12, mismatch  # the run assembles exactly this residual
# -

# Solve above and below $p^*$; each run writes its output (`interface.png` shows the aperture
# against the layer) under `out/`.

# +
results = {}
for p_net in (1e6, -1e6):
    scene = fracture(p_net)
    out = f"out/propped-fracture-{'open' if p_net > 0 else 'closing'}"
    numerics = scene.default_numerics(method="al-ssn", r0=10.0)
    results[p_net] = scene.run(numerics, out=out, verbose=False)
# -

# The numbers to check: they agree between serial and parallel runs. Open, the smallest
# aperture on the layer is at its end nodes, near Sneddon's $3.25 h_p$ at $|x| = b$.

# +
if MPI.COMM_WORLD.rank == 0:
    print(f"method.residual vs the formula: relative difference {mismatch:.1e}")
    print(f"p* = {closing.p_star():.4e} Pa")
    res = results[1e6]
    ref = res.reference
    print(
        f"p_net = +1 MPa: proppant force {res.interface.proppant_force:.2e}, K_I / K_I exact "
        f"{ref['K_I'] / ref['K_I_exact']:.4f}, opening L2 error {res.errors['opening_L2_rel']:.4f}"
    )
    print(f"  min aperture on the layer / h {ref['min_aperture_propped_over_h']:.4f}")
    res = results[-1e6]
    b, h_p = closing.p.proppant_half_length, closing.p.proppant_thickness
    print(
        f"p_net = -1 MPa: contact force {res.force:.4e}, proppant force "
        f"{res.interface.proppant_force:.4e} (2 b |p_net| = {2.0 * b * 1e6:.4e})"
    )
    print(
        f"  min aperture on the layer / h {res.interface.min_aperture_propped / h_p:.8f}, "
        f"closed length {res.contact_size:.4f}"
    )
# -
