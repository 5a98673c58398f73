# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
#       format_version: '1.5'
# ---

# # Hertz line contact with a normal-compliance law
#
# This demo solves the Hertz indentation of `hertz2d_nitsche.py` with a normal-compliance law
# instead of the Signorini conditions: the surfaces may interpenetrate, and the pressure is a
# power of the interpenetration.
#
# It illustrates how to:
#
# - choose a contact method by name and set its options (`penalty`, `exponent`),
# - write the method's residual in UFL and check that it is the one the run assembles,
# - check that the exponent $m = 1$ reproduces the penalty method,
# - read the force, the contact half-width, the peak pressure and the penetration.
#
# ## Equations
#
# The elastic problem, the block, the cylinder and the gap $g(u) = x^2 / (2 R) - (u_y + \delta)$
# are those of `hertz2d_nitsche.py`. On $\Gamma_C$ the contact law is now the normal-compliance
# law (Oden & Martins 1985, doi:10.1016/0045-7825(85)90009-X; Klarbring, Mikelic & Shillor
# 1988, doi:10.1016/0020-7225(88)90038-6)
#
# $$
# p(u) = \kappa_0 E \left( \frac{[-g(u)]_+}{h} \right)^m, \qquad \sigma_T(u) = 0,
# $$
#
# where $[-g]_+$ is the interpenetration, a model of the surface asperities being flattened,
# $h$ the local mesh size and $\kappa_0$ dimensionless (the `penalty` option). $h$ is continuous
# along $\Gamma_C$: at each node the length-weighted mean of the cell diameters of its facets,
# interpolated linearly between the nodes. With each facet's own cell diameter, two neighbouring
# facets of different sizes would have different stiffnesses, and a smooth pressure would ask
# the (continuous) interpenetration to jump at the node between them. The weak form:
# find $u \in V$ (zero on $\Gamma_D$) such that for all $v \in V$
#
# $$
# R(u; v) = \int_\Omega \sigma(u) : \varepsilon(v) \, \mathrm{d}x
# + \int_{\Gamma_C} p(u) \, v \cdot n \, \mathrm{d}s = 0, \qquad n = e_y.
# $$
#
# For $m = 1$ this is the penalty method $p = \kappa [-g]_+$, $\kappa = \kappa_0 E / h$ (Kikuchi &
# Oden 1988, doi:10.1137/1.9781611970845): the two runs must give the same force to round-off.
# For $m > 1$ the law is smooth (its derivative $m \kappa_0 E [-g]_+^{m-1} / h^m$ vanishes at
# $g = 0$) but softer near $g = 0$: a pressure $p$ needs the interpenetration
# $h \, (p / (\kappa_0 E))^{1/m}$, which grows with $m$ when $p \ll \kappa_0 E$. The
# interpenetration takes part of the prescribed depth, so the force drops and the pressure
# spreads beyond Hertz's half-width (docs/verification.md section 1 for the closed form, which
# holds for the Signorini conditions only).
#
# ## A method is one module and one line
#
# A contact method is a frozen dataclass with its parameters, a `pressure(s)` and a
# `residual(s)` written in UFL on a contact surface `s` (here
# `contactfx/contact/compliance.py`), and one line in `contactfx/contact/registry.py` that names it:
#
#     "compliance": "contactfx.contact.compliance:NormalCompliance",
#
# Its parameters then become fields of `Numerics` and command-line options (`--penalty`,
# `--exponent`), and the driver, the post-processing and `run.json` handle it without further
# code.
#
# ## Data
#
# As in `hertz2d_nitsche.py`: $R = 1$, $E = 1000$, $\nu = 0.3$, $\delta = 1.5 \cdot 10^{-3}$,
# element size $h = 3 \cdot 10^{-3}$ at the contact; $\kappa_0 = 10$, $m = 1, 1.5, 2$.
#
# ## Implementation

# +
import ufl
from mpi4py import MPI

from contactfx.contact.registry import METHODS
from contactfx.driver import setup
from contactfx.scenes.hertz import Hertz2D
from contactfx.validation.residual import random_state, relative_difference

scene = Hertz2D(Hertz2D.Params(radius=1.0, depth=1.5e-3, E=1000.0, nu=0.3))
kappa0 = 10.0
if MPI.COMM_WORLD.rank == 0:
    print(f"compliance: {METHODS['compliance']}")
# -

# The law and its residual, written as above on the contact surface `s` (state `s.u`, test
# function `s.v`, gap `s.gap()`, normal `s.normal()`, modulus `s.E`, continuous mesh size
# `s.h_continuous`, measure `s.ds` of $\Gamma_C$):


# +
def compliance_residual(s, kappa0, m):
    p = kappa0 * s.E * (ufl.max_value(-s.gap(), 0.0) / s.h_continuous) ** m
    return p * ufl.dot(s.v, s.normal()) * s.ds


# -

# The check that this is what the run assembles: build the problem `scene.run` solves (`setup`), put
# the indenter at its final depth, take an arbitrary state (random nodal values) and compare the
# assembled residual vectors, for $m = 1.5$ and, at $m = 1$, with the penalty method's.


# +
num = scene.default_numerics(method="compliance", penalty=kappa0, exponent=1.5)
method = num.method_object()  # NormalCompliance(kappa0=10.0, exponent=1.5)
problem = setup(scene, num)
problem.apply_load(1.0)
random_state(problem.state, scene.p.depth)
s = problem.surface
F_run = method.residual(s)
mismatch = relative_difference(F_run, compliance_residual(s, num.penalty, num.exponent))
penalty_method = scene.default_numerics(method="penalty", penalty=kappa0).method_object()
F_pen = penalty_method.residual(s)
mismatch_pen = relative_difference(F_pen, compliance_residual(s, num.penalty, 1.0))
assert mismatch < 1e-12 and mismatch_pen < 1e-12, (mismatch, mismatch_pen)  # exactly these
if MPI.COMM_WORLD.rank == 0:
    print(f"method.residual vs the formula (m = 1.5): relative difference {mismatch:.1e}")
    print(f"penalty's residual vs the formula (m = 1): relative difference {mismatch_pen:.1e}")
# -

# Solve with the penalty method and with the compliance law for the three exponents. Each run
# returns a `contactfx.results.RunSummary`; `reference` holds Hertz's $a$ and $p_0$ at the
# computed force.

# +
pen = scene.run(scene.default_numerics(method="penalty", penalty=kappa0), verbose=False)
runs = {}
for m in (1.0, 1.5, 2.0):
    num = scene.default_numerics(method="compliance", penalty=kappa0, exponent=m)
    runs[m] = scene.run(num, verbose=False)
# -

# The check: $m = 1$ is the penalty method, to round-off.

# +
same = abs(runs[1.0].force - pen.force) / pen.force
assert same < 1e-10, same
if MPI.COMM_WORLD.rank == 0:
    print(f"penalty        force {pen.force:.8f}")
    print(f"compliance m=1 force {runs[1.0].force:.8f}, relative difference {same:.1e}")
# -

# How the exponent changes the contact: the force, the half-width $a$ and peak pressure $p_0$
# against Hertz's at the computed force, the largest interpenetration at the nodes and its
# estimate $h (p_0 / (\kappa_0 E))^{1/m}$.

# +
h, E = scene.p.h_contact, scene.p.E
if MPI.COMM_WORLD.rank == 0:
    print("  m  force     a (Hertz)          p0 (Hertz)         penetration (estimate)  Newton")
    for m, res in runs.items():
        ref = res.reference
        estimate = h * (res.peak_pressure / (kappa0 * E)) ** (1.0 / m)
        print(
            f"{m:.1f}  {res.force:.6f}  {res.contact_size:.5f} ({ref['a']:.5f})  "
            f"{res.peak_pressure:.4f} ({ref['p0']:.4f})  {res.max_penetration:.4e} "
            f"({estimate:.2e})   {res.newton_iterations}"
        )
# -
