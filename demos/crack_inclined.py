# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
#       format_version: '1.5'
# ---

# # An inclined crack under compression with Coulomb friction: $K_{II}$
#
# This demo compresses a plate containing a closed, inclined crack whose faces carry Coulomb
# friction, and compares the mode II stress intensity factor with its closed form when the
# faces slide, and the absence of slip when they stick.
#
# It illustrates how to:
#
# - choose the friction law, its coefficient and the method (Nitsche or the augmented
#   Lagrangian),
# - write Nitsche's frictional contact residual on the crack faces and check that it is the one
#   the run assembles,
# - read $K_{II}$, the slipping fraction and the face forces from the typed run summary.
#
# ## Equations
#
# The crack $\Gamma$ ($|s| < a$ along the direction at the angle $\beta$ to the $x$ axis, unit
# normal $n_I$) lies in the plate $\Omega = (-W/2, W/2)^2$ under the uniaxial compression
# $\sigma$ along $y$. Take the upper face as the body: its outward normal is $n = -n_I$, its
# motion relative to the lower face is the jump $[\![w]\!]$, and its traction is
# $\sigma(w) n = -P n + t_T$. Find $w$ with
#
# $$
# \begin{aligned}
# -\nabla \cdot \sigma(w) &= 0 \quad \text{in } \Omega \setminus \Gamma, \qquad
# \sigma(w) n = \sigma^\infty n \quad \text{on } \partial \Omega, \\
# g = [\![w]\!] \cdot n_I \ge 0, \quad P \ge 0, \quad P g &= 0, \qquad
# |t_T| \le \mu P, \quad
# t_T = -\mu P \frac{\dot{[\![w]\!]}_T}{|\dot{[\![w]\!]}_T|}
# \ \text{where } \dot{[\![w]\!]}_T \ne 0 \quad \text{on } \Gamma,
# \end{aligned}
# $$
#
# with $\sigma^\infty$ the stress of the same crack in an infinite plate, so that the only
# error is the discretisation's. Nitsche's method (Chouly, Hild, Lleras & Renard 2022,
# doi:10.1016/j.cam.2022.114557; on crack faces with the averaged stress $\{\sigma\}$) uses the
# pressure and the tangential traction
#
# $$
# P_\gamma(w) = [-\{\sigma_n(w)\} - \gamma g]_+, \qquad
# T_\gamma(w) = \mathrm{proj}_{B(0, \mu P_\gamma(w))} \left(\{\sigma_T(w)\}
# - \gamma \Delta [\![w]\!]_T \right),
# $$
#
# where $\sigma_n = n \cdot \sigma n$, $\sigma_T = (I - n n) \sigma n$, $\gamma = \gamma_0 E /
# \{h\}$ and $\Delta [\![w]\!]_T$ the tangential slip since the last load step. With the elastic
# residual and the boundary load, the contact terms of the weak form are
#
# $$
# \int_\Gamma P_\gamma(w) \left( [\![v]\!] \cdot n - \frac{\theta}{\gamma} \{\sigma_n(v)\}
# \right) - \frac{\theta}{\gamma} \{\sigma_n(w)\} \{\sigma_n(v)\}
# - T_\gamma(w) \cdot \left( [\![v]\!] - \frac{\theta}{\gamma} \{\sigma_T(v)\} \right)
# - \frac{\theta}{\gamma} \{\sigma_T(w)\} \cdot \{\sigma_T(v)\} \, \mathrm{d}S.
# $$
#
# The crack plane carries $\sigma_n = \sigma \cos^2 \beta$ and $\tau = \sigma \sin \beta \cos
# \beta$. The faces stick while $\tan \beta \le \mu$; otherwise the whole crack slides under the
# face shear $\mu \sigma_n$ and $K_{II} = \sigma \sqrt{\pi a} \cos \beta (\sin \beta - \mu \cos
# \beta)$ (docs/verification.md section 6), estimated from the slip near the tips by
# displacement extrapolation (Chan, Tuba & Wilson 1970, doi:10.1016/0013-7944(70)90026-3).
#
# ## Data
#
# $E = 10$ GPa, $\nu = 0.25$, $a = 1$ m, $W = 20$ m, $\sigma = 10$ MPa; sliding: $\beta = 45$
# degrees, $\mu = 0.3$ ($K_{II} / (\sigma \sqrt{\pi a}) = 0.35$), with Nitsche ($\theta = 1$,
# $\gamma_0 = 10$) and with the augmented Lagrangian (semi-smooth Newton, `al-ssn`); sticking:
# $\beta = 30$ degrees, $\mu = 0.6$, Nitsche. One load step.
#
# ## Implementation

# +
import ufl
from mpi4py import MPI

from contactfx.driver import setup
from contactfx.scenes.crack import CrackInclined
from contactfx.validation.residual import random_state, relative_difference

sliding = CrackInclined(CrackInclined.Params(beta=45.0, sigma=10e6))
num = sliding.default_numerics(method="nitsche", theta=1, gamma0=10.0, friction="coulomb", mu=0.3)
method = num.method_object()
# -

# The contact terms, on the crack's contact surface `s`: `s.normal()` $= n = -n_I$, `s.u`
# $= [\![w]\!]$, `s.v` $= [\![v]\!]$, `s.stress` $= \{\sigma(w)\}$, `s.stress_test`
# $= \{\sigma(v)\}$, `s.gap()` the opening, `s.slip_increment(n)` $= \Delta [\![w]\!]_T$, `s.h`
# $= \{h\}$ and `s.ds` the interior-facet measure of $\Gamma$.


# +
def coulomb_nitsche_residual(s, theta, gamma0, mu):
    n = s.normal()
    gamma = gamma0 * s.E / s.h

    def sigma_n(stress):
        return ufl.dot(n, ufl.dot(stress, n))

    def sigma_T(stress):
        return ufl.dot(stress, n) - sigma_n(stress) * n

    P = ufl.max_value(-sigma_n(s.stress) - gamma * s.gap(), 0.0)
    trial = sigma_T(s.stress) - gamma * s.slip_increment(n)
    size = ufl.sqrt(ufl.dot(trial, trial))
    T = ufl.conditional(ufl.le(size, mu * P), trial, mu * P / size * trial)
    normal = P * (ufl.dot(s.v, n) - theta / gamma * sigma_n(s.stress_test))
    normal -= theta / gamma * sigma_n(s.stress) * sigma_n(s.stress_test)
    tangential = -ufl.dot(T, s.v - theta / gamma * sigma_T(s.stress_test))
    tangential -= theta / gamma * ufl.dot(sigma_T(s.stress), sigma_T(s.stress_test))
    return (normal + tangential) * s.ds


# -

# The check that it is what the run assembles: build the problem `scene.run` solves (`setup`), take
# an arbitrary state (random nodal values) and compare the assembled vectors.


# +
problem = setup(sliding, num)
problem.apply_load(1.0)
random_state(problem.state, 1e-4)
s = problem.surface
F_run = method.residual(s)
mismatch = relative_difference(F_run, coulomb_nitsche_residual(s, num.theta, num.gamma0, num.mu))
assert mismatch < 1e-12, mismatch  # the run assembles exactly this residual
# -

# Solve: the sliding crack with both methods (the Nitsche run writes its output, with the slip
# and the tractions along the crack in `out/crack-inclined/interface.png`), then the sticking
# crack.

# +
slide = sliding.run(num, verbose=False, out="out/crack-inclined")
slide_al = sliding.run(sliding.default_numerics(method="al-ssn", mu=0.3), verbose=False)
sticking = CrackInclined(CrackInclined.Params(beta=30.0, sigma=10e6))
stick = sticking.run(sticking.default_numerics(method="nitsche", mu=0.6), verbose=False)
# -

# The numbers to check: they agree between serial and parallel runs. The forces on the crack
# are compared with $2 a \sigma_n$ and $2 a$ times the face shear ($\mu \sigma_n$ when sliding,
# $\tau$ when sticking); the augmented Lagrangian's multiplier is zero at the tip nodes, which
# takes about 0.1 % off its forces.

# +
a = sliding.p.crack_half_length
if MPI.COMM_WORLD.rank == 0:
    print(f"method.residual vs the formula: relative difference {mismatch:.1e}")
    for name, res in (("nitsche", slide), ("al-ssn ", slide_al)):
        ref = res.reference
        normal = res.force / (2.0 * a * ref["sigma_n"])
        tangential = abs(res.interface.tangential_force) / (2.0 * a * num.mu * ref["sigma_n"])
        print(
            f"sliding, {name}: K_II / (sigma sqrt(pi a)) = {ref['K_II_normalised']:.4f} (closed "
            f"form {ref['K_II_normalised_exact']:.4f}), slipping fraction "
            f"{ref['slipping_fraction']:.3f}"
        )
        print(
            f"  normal force / (2 a sigma_n) {normal:.4f}, "
            f"tangential force / (2 a mu sigma_n) {tangential:.4f}"
        )
    ref = stick.reference
    normal = stick.force / (2.0 * a * ref["sigma_n"])
    tangential = abs(stick.interface.tangential_force) / (2.0 * a * abs(ref["tau"]))
    print(f"sticking: max slip {ref['max_slip']:.3e}")
    print(
        f"  normal force / (2 a sigma_n) {normal:.4f}, "
        f"tangential force / (2 a tau) {tangential:.4f}"
    )
# -
