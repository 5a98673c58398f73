# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
#       format_version: '1.5'
# ---

# # Westergaard's wavy surface: convergence of Nitsche's method in full contact
#
# This demo presses an elastic half-plane on a rigid sinusoid with a mean pressure large enough
# for complete contact, where the exact displacement is known, and measures the convergence of
# the three variants of Nitsche's method under mesh refinement.
#
# It illustrates how to:
#
# - drive a scene by force (a traction on the bottom of the strip) over the scene's default
#   load steps,
# - write the contact residual in UFL and check that it is the one the run assembles,
# - read the errors against an exact displacement field and estimate convergence rates.
#
# ## Equations
#
# The half period $\Omega = (0, \lambda / 2) \times (-H, 0)$ of an elastic strip rests on the
# rigid surface $z = \Delta (1 - \cos(2 \pi x / \lambda))$ above it and is pushed up by the mean
# pressure $p_m$ on its bottom $\Gamma_B$; its sides are symmetry planes. Find $u$ with
#
# $$
# \begin{aligned}
# -\nabla \cdot \sigma(u) &= 0 \quad \text{in } \Omega, \qquad
# u_x = 0 \quad \text{at } x = 0, \lambda / 2, \qquad
# \sigma(u) n = p_m e_y \quad \text{on } \Gamma_B, \\
# g(u) \ge 0, \quad p \ge 0, \quad p \, g(u) &= 0, \quad \sigma_T(u) = 0
# \quad \text{on the top } \Gamma_C,
# \end{aligned}
# $$
#
# with $n = e_y$, $p = -\sigma_n(u)$ and the linearised gap
# $g(u) = \Delta (1 - \cos(2 \pi x / \lambda)) - u_y$. With Nitsche's method (Chouly, Hild &
# Renard 2015, doi:10.1090/S0025-5718-2014-02913-X), $P_\gamma(u) = [-\sigma_n(u) -
# \gamma g(u)]_+$ and $\gamma = \gamma_0 E / h$: find $u \in V$ such that for all $v \in V$
#
# $$
# \int_\Omega \sigma(u) : \varepsilon(v) \, \mathrm{d}x
# - \int_{\Gamma_B} p_m v_y \, \mathrm{d}s
# - \int_{\Gamma_C} \frac{\theta}{\gamma} \sigma_n(u) \sigma_n(v) \, \mathrm{d}s
# + \int_{\Gamma_C} P_\gamma(u) \left( v \cdot n - \frac{\theta}{\gamma} \sigma_n(v) \right)
# \mathrm{d}s = 0.
# $$
#
# Nothing holds the strip vertically but the contact: the scene starts Newton from a lifted
# state that overlaps the obstacle.
#
# Above $p^* = \pi E^* \Delta / \lambda$ the contact is complete, $p(x) = p_m + p^* \cos(2 \pi x /
# \lambda)$ (Westergaard 1939, doi:10.1115/1.4008969), and the displacement is smooth and known
# in closed form (docs/verification.md section 3): P1 elements must converge at the optimal
# rates, $O(h^2)$ in $L^2$ and $O(h)$ in the $H^1$ semi-norm.
#
# ## Data
#
# $\lambda = 1$, $\Delta = 0.01$, $E = 1000$, $\nu = 0.3$, $p_m = 1.5 p^*$; uniform meshes
# $h = 1/16, 1/32, 1/64, 1/128$; $\theta = 1, 0, -1$ with $\gamma_0 = 10$; the scene's two load
# steps. The strip is $H = 3 \lambda$ deep: the uniform traction at its bottom departs from the
# half-plane's field by the relative $(1 + kH) e^{-kH}$, $k = 2 \pi / \lambda$, which is
# $5 \cdot 10^{-5}$ at the scene's default $H = 2 \lambda$, enough to bend the $L^2$ rate on the
# finest mesh (1.86 instead of 1.97), and $10^{-7}$ at $H = 3 \lambda$.
#
# ## Implementation

# +
import numpy as np
import ufl
from mpi4py import MPI

from contactfx.driver import setup
from contactfx.scenes.westergaard import Westergaard
from contactfx.validation.residual import random_state, relative_difference


def scene_at(h):
    params = Westergaard.Params(mean_pressure_ratio=1.5, depth_ratio=3.0, h_contact=h, h_far=h)
    return Westergaard(params)


num = scene_at(1 / 16).default_numerics(method="nitsche", theta=-1, gamma0=10.0)
# -

# `default_numerics` keeps the scene's two load steps (`Numerics(...)` would start from one).
# The contact term of the weak form on the contact surface `s` (state `s.u`, test function
# `s.v`, stresses `s.stress` and `s.stress_test`, gap `s.gap()`, normal `s.normal()`, modulus
# `s.E`, cell size `s.h`, measure `s.ds` of $\Gamma_C$):


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

# The check that it is what the run assembles: build the problem `scene.run` solves (`setup`), apply
# the full load, take an arbitrary state (random nodal values) and compare the assembled vectors.


# +
scene = scene_at(1 / 16)
method = num.method_object()
problem = setup(scene, num)
problem.apply_load(1.0)
random_state(problem.state, scene.p.amplitude)
s = problem.surface
F_run = method.residual(s)
mismatch = relative_difference(F_run, nitsche_residual(s, num.theta, num.gamma0))
assert mismatch < 1e-12, mismatch  # the run assembles exactly this residual
if MPI.COMM_WORLD.rank == 0:
    print(f"load steps {num.steps}")
    print(f"method.residual vs the formula: relative difference {mismatch:.1e}")
# -

# Solve on each mesh with each variant. The run summary's `errors` holds the displacement
# errors in $L^2$ and in the $H^1$ semi-norm and the relative $L^2$ error of the pressure on
# $\Gamma_C$, all against the closed form.

# +
sizes = [1 / 16, 1 / 32, 1 / 64, 1 / 128]
errors = {}
for theta in (1, 0, -1):
    rows = []
    for h in sizes:
        scene = scene_at(h)
        num = scene.default_numerics(method="nitsche", theta=theta, gamma0=10.0)
        res = scene.run(num, verbose=False)
        e = res.errors
        rows.append((e["displacement_L2"], e["displacement_H1"], e["pressure_L2_rel"]))
    errors[theta] = np.array(rows)
# -

# The errors, the observed rates between consecutive meshes, $\log_2(e_h / e_{h/2})$, and the
# least-squares rate over the four meshes: 2 in $L^2$, 1 in $H^1$ (the unstructured meshes
# make the consecutive rates scatter by a few hundredths).

# +
if MPI.COMM_WORLD.rank == 0:
    for theta, e in errors.items():
        print(f"theta = {theta:2d}:       h  u L2        u H1        p L2 (rel.)")
        for h, (l2, h1, p) in zip(sizes, e, strict=True):
            print(f"           {h:.5f}  {l2:.4e}  {h1:.4e}  {p:.4e}")
        rates = np.log2(e[:-1] / e[1:])
        fit = np.polyfit(np.log2(sizes), np.log2(e), 1)[0]
        for name, column, slope in zip(("u L2", "u H1", "p L2"), rates.T, fit, strict=True):
            steps = "  ".join(f"{r:.2f}" for r in column)
            print(f"  rates {name}: {steps}, least squares {slope:.2f}")
# -
