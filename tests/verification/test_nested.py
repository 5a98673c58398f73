"""Nested iteration (``--nested``, contactfx/driver/nested.py): the same discrete solution as
a solve from the undeformed start, in a few Newton iterations on the fine mesh
(docs/verification.md section 12). Every run here also runs under ``mpirun -n 2``."""

import dolfinx
import numpy as np
import pytest
from mpi4py import MPI

from contactfx import _compat
from contactfx.driver.nested import Transfer, nested_levels, transfer
from contactfx.scenes.hertz import Hertz2D, Hertz2DParams
from contactfx.scenes.two_body import PatchTest, PatchTestParams

# 17516 dofs: one coarser level (8.8e3 dofs) above nested.MIN_DOFS; 64976 dofs: two
FINE = Hertz2DParams(h_contact=1.5e-3)
FINER = Hertz2DParams(h_contact=7.5e-4)


def _pair(params, nested, **numerics):
    num = Hertz2D.default_numerics(**numerics)
    plain = Hertz2D(params).run(num, verbose=False)
    chain = Hertz2D(params).run(Hertz2D.default_numerics(nested=nested, **numerics), verbose=False)
    return plain, chain


def _assert_same(plain, chain):
    # both solve the same discrete equations to snes_rtol 1e-10 (relative to the first
    # residual): the force agrees to ~1e-10 of its size, far below 1e-8; the contact size is
    # a sum over the same active quadrature points (identical), the peak pressure a nodal
    # value of the same solution
    assert chain.force == pytest.approx(plain.force, rel=1e-8)
    assert chain.contact_size == pytest.approx(plain.contact_size, rel=1e-12)
    assert chain.quantities.peak_pressure == pytest.approx(plain.quantities.peak_pressure, rel=1e-8)


@pytest.mark.parametrize("method", ["nitsche", "penalty", "al-ssn"])
def test_nested_same_solution_fewer_iterations(method):
    plain, chain = _pair(FINE, 2, method=method)
    _assert_same(plain, chain)
    # the coarse chain ran (one level: 17516 / 4 dofs >= MIN_DOFS, / 16 below)
    assert chain.steps[0].coarse_newton > 0
    # started within a coarse element of the contact edge, the fine solve needs at most 3
    # iterations (measured 1-3 at every bench level up to 2.5e5 dofs; 8-12 from the
    # undeformed start)
    assert chain.newton_iterations <= 3 < plain.newton_iterations


def test_nested_uzawa_carries_the_multiplier():
    """al-uzawa: the nodal multiplier comes from the coarse mesh too (fewer outer
    iterations), the converged solution is the same to the Uzawa tolerance 1e-8."""
    plain, chain = _pair(FINE, 1, method="al-uzawa")
    assert chain.force == pytest.approx(plain.force, rel=1e-7)
    # the contact size follows p and g continuously (the zero contour of p - (E* / h) g; the
    # closed set's measure was the same to the bit): 6e-11 apart
    assert chain.contact_size == pytest.approx(plain.contact_size, rel=1e-9)
    assert chain.outer_iterations < plain.outer_iterations


def test_nested_two_levels():
    plain, chain = _pair(FINER, 3, method="nitsche")
    _assert_same(plain, chain)
    assert chain.newton_iterations <= 3
    assert "nested" in chain.timings and chain.timings["nested"] > 0.0


def test_nested_levels_rule():
    assert nested_levels(3, 250034, 2) == 3  # 250034 / 64 = 3907 >= 2000
    assert nested_levels(2, 250034, 2) == 2  # capped by the request
    assert nested_levels(3, 64976, 2) == 2  # 64976 / 64 = 1015 < 2000
    assert nested_levels(3, 1712, 2) == 0
    assert nested_levels(3, 113000, 3) == 1  # 3D: 113000 / 8 >= 2000 > 113000 / 64


@pytest.mark.parametrize("degree", [1, 2])
def test_transfer_reproduces_polynomials(degree):
    """A field of the coarse space's degree is interpolated exactly on a mesh that does not
    nest in the coarse one (round-off: 1e-12)."""
    comm = MPI.COMM_WORLD
    corners = [np.array([0.0, 0.0]), np.array([1.0, 1.0])]
    coarse_mesh = dolfinx.mesh.create_rectangle(comm, corners, [4, 3])
    fine_mesh = dolfinx.mesh.create_rectangle(comm, corners, [7, 9])

    def field(x):
        if degree == 1:
            return np.vstack([1.0 + 2.0 * x[0] - x[1], 3.0 * x[0] + x[1]])
        return np.vstack([x[0] * x[1] - x[1] ** 2, 1.0 + x[0] ** 2])

    Vc = _compat.function_space(coarse_mesh, "Lagrange", degree, (2,))
    Vf = _compat.function_space(fine_mesh, "Lagrange", degree, (2,))
    uc, uf, exact = (dolfinx.fem.Function(V) for V in (Vc, Vf, Vf))
    uc.interpolate(field)
    exact.interpolate(field)
    assert transfer(uc, uf, split=False) == 0
    n = Vf.dofmap.index_map.size_local * 2
    assert np.max(np.abs(uf.x.array[:n] - exact.x.array[:n]), initial=0.0) < 1e-12
    # ghosts follow the owners
    assert np.max(np.abs(uf.x.array - exact.x.array)) < 1e-12


def test_transfer_keeps_fixed_dofs_and_repeats():
    """The ``fixed`` dofs (a field confined to a surface) keep their value, the others are
    interpolated exactly (P1 field, round-off 1e-12); a second call, with the coarse cells
    found at the first, interpolates the changed coarse field exactly too."""
    comm = MPI.COMM_WORLD
    corners = [np.array([0.0, 0.0]), np.array([1.0, 1.0])]
    coarse_mesh = dolfinx.mesh.create_rectangle(comm, corners, [4, 3])
    fine_mesh = dolfinx.mesh.create_rectangle(comm, corners, [7, 9])
    Vc = _compat.function_space(coarse_mesh, "Lagrange", 1, (2,))
    Vf = _compat.function_space(fine_mesh, "Lagrange", 1, (2,))
    uc, uf, exact = (dolfinx.fem.Function(V) for V in (Vc, Vf, Vf))
    # fixed: both components of the nodes with x < 0.5, the y component of those with y < 0.3
    x = _compat.dof_coordinates(Vf)
    both = np.repeat(x[:, 0] < 0.5, 2)
    y_only = np.repeat(x[:, 1] < 0.3, 2) & (np.arange(len(both)) % 2 == 1)
    fixed = np.flatnonzero(both | y_only)
    free = np.setdiff1d(np.arange(len(uf.x.array)), fixed)
    moving = Transfer(uc, uf, split=False, fixed=fixed)
    for k in (1.0, -3.0):

        def field(x, k=k):
            return np.vstack([k + 2.0 * x[0] - x[1], 3.0 * k * x[0] + x[1]])

        uc.interpolate(field)
        exact.interpolate(field)
        uf.x.array[fixed] = 7.0
        assert moving() == 0
        assert np.all(uf.x.array[fixed] == 7.0)
        assert np.max(np.abs(uf.x.array[free] - exact.x.array[free]), initial=0.0) < 1e-12


def test_nested_refused_where_not_offered():
    with pytest.raises(ValueError, match="obstacle scenes"):
        PatchTest(PatchTestParams()).run(PatchTest.default_numerics(nested=1), verbose=False)
    with pytest.raises(ValueError, match="nested"):
        Hertz2D.default_numerics(nested=-1)


def test_bench_method_suffix():
    from contactfx.validation.bench import expand_methods

    assert expand_methods("nitsche@1+nested2") == [
        ("nitsche(1) nested2", {"method": "nitsche", "theta": 1, "nested": 2})
    ]
    with pytest.raises(ValueError, match=r"\+nested2"):
        expand_methods("penalty+nested")
