# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
#       format_version: '1.5'
# ---

# # Hertz line contact with Nitsche's method
#
# This demo presses a rigid cylinder into an elastic plane-strain block, with the Signorini
# contact conditions imposed by Nitsche's method, and compares the contact half-width and peak
# pressure with Hertz's closed form.
#
# It illustrates how to:
#
# - set up a scene and start from its default numerics,
# - write Nitsche's contact residual in UFL and check that it is the residual the run assembles,
# - read the contact force, half-width and peak pressure from the typed run summary,
# - run the same script serially and with `mpirun -n 2`.
#
# ## Equations
#
# The block $\Omega = (-1, 1) \times (-1, 0)$ is clamped at its bottom $\Gamma_D$; its top
# $\Gamma_C$ may touch the cylinder of radius $R$, pushed down by the depth $\delta$. Find the
# displacement $u$ with
#
# $$
# \begin{aligned}
# -\nabla \cdot \sigma(u) &= 0 \quad \text{in } \Omega, \qquad
# \sigma(u) = 2 \mu \varepsilon(u) + \lambda \operatorname{tr} \varepsilon(u) I, \qquad
# u = 0 \quad \text{on } \Gamma_D, \\
# g(u) \ge 0, \quad p \ge 0, \quad p \, g(u) &= 0, \quad \sigma_T(u) = 0
# \quad \text{on } \Gamma_C,
# \end{aligned}
# $$
#
# with the contact pressure $p = -\sigma_n(u) = -n \cdot \sigma(u) n$, $n = e_y$, and Hertz's
# linearised gap $g(u) = x^2 / (2 R) - (u_y + \delta)$ (the `parabola` profile: the gap is
# measured vertically and the pressure acts vertically).
#
# Nitsche's method (Chouly, Hild & Renard 2015, doi:10.1090/S0025-5718-2014-02913-X) writes
# the three conditions as one equation, $p = P_\gamma(u) = [-\sigma_n(u) - \gamma g(u)]_+$ with
# $\gamma = \gamma_0 E / h$ ($h$ the diameter of the cell at the facet), and the weak form is:
# find $u \in V$ (zero on $\Gamma_D$) such that for all $v \in V$
#
# $$
# R(u; v) = \int_\Omega \sigma(u) : \varepsilon(v) \, \mathrm{d}x
# - \int_{\Gamma_C} \frac{\theta}{\gamma} \sigma_n(u) \sigma_n(v) \, \mathrm{d}s
# + \int_{\Gamma_C} P_\gamma(u) \left( v \cdot n - \frac{\theta}{\gamma} \sigma_n(v) \right)
# \mathrm{d}s = 0.
# $$
#
# $\theta = 1$ is the symmetric variant (it needs $\gamma_0$ large enough), $\theta = -1$ the
# skew-symmetric one (stable for every $\gamma_0 > 0$), $\theta = 0$ the incomplete one.
#
# Hertz (docs/verification.md section 1), at the computed force $P$ per unit length:
# $a = \sqrt{4 P R / (\pi E^*)}$, $p_0 = 2 P / (\pi a)$, $E^* = E / (1 - \nu^2)$.
#
# ## Data
#
# $R = 1$, $E = 1000$, $\nu = 0.3$, $\delta = 1.5 \cdot 10^{-3}$ (so $a / R \approx 0.026$),
# element size $3 \cdot 10^{-3}$ on $|x| < 0.06$ and $0.1$ elsewhere; $\theta = 1$,
# $\gamma_0 = 10$, P1 elements, one load step.
#
# ## Implementation
#
# The scene holds the geometry, the obstacle and the closed form. Its numerics start from
# `default_numerics`, which keeps the scene's own choices (load steps, friction) and overrides
# only what is named.

# +
import ufl
from mpi4py import MPI

from contactfx.driver import setup
from contactfx.scenes.hertz import Hertz2D
from contactfx.validation.residual import random_state, relative_difference

scene = Hertz2D(Hertz2D.Params(radius=1.0, depth=1.5e-3, E=1000.0, nu=0.3))
num = scene.default_numerics(method="nitsche", theta=1, gamma0=10.0)
method = num.method_object()  # contactfx.contact.nitsche.Nitsche(theta=1, gamma0=10.0)
# -

# The contact term of $R(u; v)$, written as above on a contact surface `s`. The surface
# (`contactfx.contact.gap.ContactSurface`) holds the state `s.u` and test function `s.v`, their
# stresses `s.stress` $= \sigma(u)$ and `s.stress_test` $= \sigma(v)$, the gap `s.gap()`, the
# normal `s.normal()`, the modulus `s.E`, the cell size `s.h` and the measure `s.ds` of
# $\Gamma_C$.


# +
def nitsche_residual(s, theta, gamma0):
    n = s.normal()
    gamma = gamma0 * s.E / s.h
    sigma_n_u = ufl.dot(n, ufl.dot(s.stress, n))
    sigma_n_v = ufl.dot(n, ufl.dot(s.stress_test, n))
    P = ufl.max_value(-sigma_n_u - gamma * s.gap(), 0.0)
    return (
        P * (ufl.dot(s.v, n) - theta / gamma * sigma_n_v) - theta / gamma * sigma_n_u * sigma_n_v
    ) * s.ds


# -

# This is the residual the run uses: build the problem `scene.run` solves (`setup`), put the
# indenter at its final depth, take an arbitrary state (random nodal values) and compare the
# assembled vectors of `method.residual(s)` and of the formula above.


# +
problem = setup(scene, num)
problem.apply_load(1.0)
random_state(problem.state, scene.p.depth)
s = problem.surface
F_run = method.residual(s)
mismatch = relative_difference(F_run, nitsche_residual(s, num.theta, num.gamma0))
assert mismatch < 1e-12, mismatch  # the run assembles exactly this residual
# -

# Solve. `scene.run` returns a `contactfx.results.RunSummary`: named fields for the contact
# state (`force`; `contact_size`, here the half-width $a$, half the length of the set where
# $P_\gamma > 0$; `peak_pressure`, the largest nodal pressure) and dictionaries of named floats
# for the closed-form comparison (`reference`) and the field errors (`errors`).
# `res.to_json()` is what `run.json` holds when `out` is given.

# +
res = scene.run(num, verbose=False)
ref = res.reference
# -

# The numbers to check: they agree between serial and parallel runs
# (`python3 demos/hertz2d_nitsche.py`, `mpirun -n 2 python3 demos/hertz2d_nitsche.py`, with
# the Python of the virtual environment that `scripts/install.sh` builds).

# +
if MPI.COMM_WORLD.rank == 0:
    print(f"method.residual vs the formula: relative difference {mismatch:.1e}")
    print(f"dofs {res.dofs}, Newton iterations {res.newton_iterations}")
    print(f"force P = {res.force:.8f}")
    print(f"a  = {res.contact_size:.6f} (Hertz {ref['a']:.6f}, {ref['a_error_over_h']:.2f} h)")
    print(f"p0 = {res.peak_pressure:.4f} (Hertz {ref['p0']:.4f}, {ref['p0_rel_error']:.2%})")
    print(f"pressure L2 error on the contact: {res.errors['pressure_L2_rel']:.4f}")
# -
