# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
#       format_version: '1.5'
# ---

# # The Barton-Bandis joint column
#
# This demo compresses two rock blocks stacked on rollers with a fluid-filled joint between
# them, whose closure follows the Barton-Bandis law, and reproduces the closed-form closure,
# aperture and settlement with Nitsche's method and with the augmented Lagrangian (Uzawa).
#
# It illustrates how to:
#
# - write a nonlinear joint law as a contact condition with a stress-dependent gap,
# - write the augmented Lagrangian (Uzawa) residual and check that it is the one the run
#   assembles,
# - read the joint's closure, aperture and the settlement of the top from the typed summary.
#
# ## Equations
#
# The blocks $(0, L) \times (0, H)$ and $(0, L) \times (H, 2 H)$ are joined by the joint
# $\Gamma$ at $y = H$ (unit normal $n_I = e_y$, initial aperture $w_0$). The sides are on
# rollers ($u_x = 0$), so is the bottom ($u_y = 0$); the top carries the compression $s_c$ and
# the joint the fluid pressure $p_f$. The joint closes by $v$ under the effective normal stress
# $s' = -(\sigma_n(w) + p_f)$, $\sigma_n = n_I \cdot \sigma n_I$, by the Barton-Bandis law
# (Bandis, Lumsden & Barton 1983, doi:10.1016/0148-9062(83)90595-8)
#
# $$
# v = \psi(s') = \frac{s' V_m}{K_{ni} V_m + s'}, \qquad 0 \le v < V_m,
# $$
#
# and opens freely when $s' = 0$. With the jump $[\![w]\!]$ across $\Gamma$ (the closure is
# $v = -[\![w]\!] \cdot n_I$) both cases are one Signorini condition with a stress-dependent
# gap:
#
# $$
# \begin{aligned}
# -\nabla \cdot \sigma(w) &= 0 \quad \text{in } \Omega \setminus \Gamma, \qquad
# \sigma(w) n = -s_c e_y \quad \text{on the top}, \\
# \sigma(w) n_I &= -(p_f + s') n_I, \qquad
# g(w) = [\![w]\!] \cdot n_I + \psi([s']_+) \ge 0, \quad s' \ge 0, \quad s' g(w) = 0
# \quad \text{on } \Gamma.
# \end{aligned}
# $$
#
# The augmented Lagrangian method with Uzawa's loop (Alart & Curnier 1991,
# doi:10.1016/0045-7825(91)90022-X) keeps a nodal multiplier $\lambda$ (the joint's effective
# pressure) fixed while Newton solves: for all $v$,
#
# $$
# \int_{\Omega \setminus \Gamma} \sigma(w) : \varepsilon(v) \, \mathrm{d}x
# + \int_{\text{top}} s_c v_y \, \mathrm{d}s
# - \int_\Gamma p_f [\![v]\!] \cdot n_I \, \mathrm{d}S
# - \int_\Gamma [\lambda - r g(w)]_+ [\![v]\!] \cdot n_I \, \mathrm{d}S = 0,
# \qquad r = r_0 E / \{h\},
# $$
#
# then sets $\lambda \leftarrow [\lambda - r g(w)]_+$ at the nodes, until $\lambda$ stops
# changing: the law then holds exactly at the nodes, whatever $r$. Nitsche's method uses the
# same gap with $P_\gamma = [s' - \gamma g(w)]_+$.
#
# The solution is uniform in each block: $s' = s_c - p_f$, $v = \psi(s')$, the aperture
# $w_0 - v$, the settlement of the top $2 H s_c / M + v$ with
# $M = E (1 - \nu) / ((1 + \nu)(1 - 2 \nu))$, and the joint's normal force $P = s' L$. Every
# mesh and every method reproduces the table of docs/verification.md section 7.
#
# ## Data
#
# $E = 10$ GPa, $\nu = 0.25$, $H = 1$ m, $L = 0.5$ m, $w_0 = 1$ mm, $K_{ni} = 50$ GPa/m,
# $V_m = 0.3$ mm, element size $0.25$ m; $(s_c, p_f) = (30, 10)$, $(30, 0)$ and $(60, 10)$ MPa;
# Nitsche with $\theta = 1$, $\gamma_0 = 10$; Uzawa with $r_0 = 10$. One load step.
#
# ## Implementation

# +
import ufl
from mpi4py import MPI

from contactfx.driver import setup
from contactfx.scenes.joint import JointColumn
from contactfx.validation.residual import random_state, relative_difference


def column(s_c, p_f):
    params = JointColumn.Params(
        closure_stress=s_c, fluid_pressure=p_f, aperture=1e-3, Kni=50e9, Vm=3e-4
    )
    return JointColumn(params)


scene = column(30e6, 10e6)
num = scene.default_numerics(method="al-uzawa", r0=10.0)
method = num.method_object()  # AugmentedLagrangianUzawa(r0=10.0, ...)
# -

# The contact term on the joint's surface `s`: `s.u` $= [\![w]\!]$, `s.v` $= [\![v]\!]$,
# `s.stress` $= \{\sigma(w)\} + p_f I$ (the effective stress), `s.interface_normal()` $= n_I$,
# `s.multiplier` $= \lambda$, `s.h` $= \{h\}$ and `s.ds` the interior-facet measure of $\Gamma$.


# +
def uzawa_residual(s, r0, Kni, Vm):
    n_I = s.interface_normal()
    s_eff = ufl.max_value(-ufl.dot(n_I, ufl.dot(s.stress, n_I)), 0.0)  # [s']_+
    g = ufl.dot(s.u, n_I) + s_eff * Vm / (Kni * Vm + s_eff)
    p = ufl.max_value(s.multiplier - r0 * s.E / s.h * g, 0.0)
    return -p * ufl.dot(s.v, n_I) * s.ds


# -

# The check that it is what the run assembles: build the problem `scene.run` solves (`setup`), apply
# the loads, take an arbitrary state (random nodal values of the displacement and the multiplier)
# and compare the assembled vectors.


# +
problem = setup(scene, num)
problem.apply_load(1.0)
random_state(problem.state, 1e-4)
random_state(problem.multiplier, 30e6)
s = problem.surface
F_run = method.residual(s)
mismatch = relative_difference(F_run, uzawa_residual(s, num.r0, scene.p.Kni, scene.p.Vm))
assert mismatch < 1e-12, mismatch  # the run assembles exactly this residual
# -

# Solve the three load cases with both methods; the output of the last run is in
# `out/joint-column`.

# +
rows = []
for s_c, p_f in ((30e6, 10e6), (30e6, 0.0), (60e6, 10e6)):
    scene = column(s_c, p_f)
    for name in ("nitsche", "al-uzawa"):
        numerics = scene.default_numerics(method=name, theta=1, gamma0=10.0, r0=10.0)
        rows.append((s_c, p_f, name, scene.run(numerics, verbose=False, out="out/joint-column")))
# -

# The numbers to check: they agree between serial and parallel runs, and with the table of
# docs/verification.md section 7 (171.429, 200.000, 230.769 um of closure; 5.171429,
# 5.200000, 10.230769 mm of settlement).

# +
if MPI.COMM_WORLD.rank == 0:
    print(f"method.residual vs the formula: relative difference {mismatch:.1e}")
    print(
        "s_c [MPa]  p_f [MPa]  method    closure [um]  aperture [um]  settlement [mm]  P / (s' L)"
    )
    for s_c, p_f, name, res in rows:
        ref = res.reference
        force = res.force / ((s_c - p_f) * scene.p.width)
        print(
            f"{s_c / 1e6:9.1f}  {p_f / 1e6:9.1f}  {name:8s}  {ref['closure'] * 1e6:12.3f}  "
            f"{ref['aperture'] * 1e6:13.3f}  {ref['settlement'] * 1e3:15.6f}  {force:.6f}"
        )
    keys = ("closure_rel_error", "aperture_rel_error", "settlement_rel_error")
    worst = max(res.reference[key] for *_, res in rows for key in keys)
    print(f"largest relative error against the closed form: {worst:.1e}")
# -
