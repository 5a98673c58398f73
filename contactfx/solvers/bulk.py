"""The bulk at the solver boundary: the bodies' own equations, without the contact terms.

The nonlinear solver (:class:`contactfx.solvers.snes.ContactSNES`) asks a bulk for

    R(u) = f_int(u) - f_ext        (every row, before the Dirichlet rows are replaced)
    K(u) = d f_int / du (u)

and adds the contact terms to them. Whether K depends on u is a property of the bulk
(``constant_jacobian``, as Firedrake's ``NonlinearVariationalProblem(constant_jacobian=...)``),
not an assumption of the solver:

* :class:`LinearBulk`: small-strain elasticity, f_int(u) = K u with K assembled once per run;
  a residual costs one matrix-vector product, a Jacobian none (the fast path);
* :class:`NonlinearBulk`: f_int(u) from a UFL form (e.g. the first Piola stress of a
  hyperelastic body), K(u) from ``ufl.derivative``, both assembled at every Newton iteration.

f_ext is the load form, assembled by :meth:`Bulk.assemble_load` whenever the load program
changes its constants. Anything outside the solver that needs an internal force (reactions,
the VI's contact pressure, two-body nodal forces) calls :meth:`Bulk.residual`, never a matrix.
The vectors a bulk reads and writes are the unknown's full (unreduced) PETSc vectors; its
forms read the unknown's Function, which the solver keeps equal to the iterate.
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

from petsc4py import PETSc

from contactfx import _compat

__all__ = ["Bulk", "LinearBulk", "NonlinearBulk"]

#: a compiled dolfinx form (``dolfinx.fem.form``)
Form = Any


@runtime_checkable
class Bulk(Protocol):
    """What the solver asks of the bodies' equations (see the module docstring)."""

    #: whether K(u) is the same matrix (values included) at every u
    constant_jacobian: bool
    #: f_ext, as last assembled (read only)
    load: PETSc.Vec

    def assemble_load(self) -> None:
        """Assemble f_ext for the current values of the load's constants."""

    def residual(self, x: PETSc.Vec, F: PETSc.Vec) -> None:
        """F = f_int(x) - f_ext on every row (x: the state, equal to the forms' Function)."""

    def jacobian(self, x: PETSc.Vec | None) -> PETSc.Mat:
        """K(x), assembled (owned by the bulk: do not destroy, do not modify)."""

    def create_vector(self) -> PETSc.Vec:
        """A new vector of the residual's layout (the caller destroys it)."""

    def reassemble(self) -> None:
        """Assemble K again at the next call: the constants of its forms changed (a dynamic
        stepper's new step size in the effective stiffness K + c M)."""

    def destroy(self) -> None: ...


class _BulkBase:
    """The load vector f_ext of a compiled linear form, and the matrix K."""

    constant_jacobian = True

    def __init__(self, load: Form, K: PETSc.Mat) -> None:
        self.load_form = load
        self.K = K
        self.load = _compat.create_vector(load)

    def assemble_load(self) -> None:
        _compat.assemble_vector(self.load, self.load_form)

    def create_vector(self) -> PETSc.Vec:
        return self.K.createVecLeft()

    def destroy(self) -> None:
        for obj in (self.K, self.load):
            obj.destroy()


class LinearBulk(_BulkBase):
    """f_int(u) = K u with K the compiled bilinear form ``stiffness``, assembled once;
    ``load`` the compiled linear form of f_ext."""

    constant_jacobian = True

    def __init__(self, *, stiffness: Form, load: Form) -> None:
        super().__init__(load, _compat.assemble_matrix(_compat.create_matrix(stiffness), stiffness))
        self.stiffness = stiffness

    def reassemble(self) -> None:
        """K assembled again, in place (same pattern)."""
        _compat.assemble_matrix(self.K, self.stiffness)

    def residual(self, x: PETSc.Vec, F: PETSc.Vec) -> None:
        self.K.mult(x, F)
        F.axpy(-1.0, self.load)

    def jacobian(self, x: PETSc.Vec | None) -> PETSc.Mat:
        return self.K


class NonlinearBulk(_BulkBase):
    """f_int(u) the compiled linear form ``internal`` (in the test function, nonlinear in the
    state Function it reads), K(u) the compiled ``tangent`` (its ``ufl.derivative``); both
    assembled at every call. ``load``: the compiled linear form of f_ext.

    With ``constant_jacobian=True`` the tangent is assembled at the first call only (a form
    whose derivative does not depend on u, e.g. a linear body written as a residual)."""

    def __init__(
        self, *, internal: Form, tangent: Form, load: Form, constant_jacobian: bool = False
    ) -> None:
        super().__init__(load, _compat.create_matrix(tangent))
        self.internal, self.tangent = internal, tangent
        self.constant_jacobian = constant_jacobian
        self.f = _compat.create_vector(internal)
        self._assembled = False
        self.jacobian(None)  # the pattern's values: the solver copies K before any iterate

    def reassemble(self) -> None:
        self._assembled = False

    def residual(self, x: PETSc.Vec, F: PETSc.Vec) -> None:
        _compat.assemble_vector(self.f, self.internal)
        self.f.copy(F)
        F.axpy(-1.0, self.load)

    def jacobian(self, x: PETSc.Vec | None) -> PETSc.Mat:
        if not (self.constant_jacobian and self._assembled):
            _compat.assemble_matrix(self.K, self.tangent)
            self._assembled = True
        return self.K

    def destroy(self) -> None:
        super().destroy()
        self.f.destroy()
