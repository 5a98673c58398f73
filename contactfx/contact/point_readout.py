"""What the post-processing reads of a Gauss-point coupling (:mod:`.point_coupling`): the
quadrature values of both directions lumped to the slave nodes (pressure, gap, normal,
friction), the pair's force vector, its normal force and the friction sums."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, TypeAlias

import numpy as np

if TYPE_CHECKING:
    from mpi4py import MPI

    from contactfx.contact.coupling import NodeLayout

__all__ = ["PointReadout", "State"]

#: per direction at the last residual: P, g, and with friction t_T, the stick mask, the slip
State: TypeAlias = tuple[
    np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None, np.ndarray | None
]


class PointReadout:
    """The readouts of :class:`contactfx.contact.point_coupling.PointCoupling` (its base):
    ``points`` (per direction, the Gauss points' arrays), ``state`` (per direction: P, the
    gap, t_T, stick, slip), ``dirs`` (the directions, with their weights), ``layout``,
    ``comm`` and the friction's ``mu`` / ``threshold``."""

    points: list[dict[str, np.ndarray]]
    state: list[State]
    dirs: list[Any]
    layout: NodeLayout
    comm: MPI.Comm
    mu: float | None
    threshold: float | None

    def _lumped(self, columns: list[list[np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
        """Owned contact nodes of the first direction's slave surface (those whose support
        has a master on more than half of it) and the weighted nodal means of the point values
        ``columns[k]`` of each direction k: the first direction's lumped with the slave facet's
        shape functions; the unbiased variant's second direction (points on the other
        surface, its pressure the same interface's) carried to the slave nodes by the
        barycentric coordinates of the points' projections onto the slave facets, so that the
        nodal value is the mean of both sides' laws, weighted by their halves (a side may hold
        the whole contact alone: on a concave-convex interface the polygons of the convex
        side's points stay apart from the concave one, the concave side's points close)."""
        blocks = []
        for k, (p, dr) in enumerate(zip(self.points, self.dirs, strict=True)):
            paired = np.isfinite(self.state[k][1])
            if k == 0:
                N, nodes = p["N_facet"], p["slave_nodes"]
            else:
                N, nodes = p["Nm"], p["master_nodes"]
            # the biased variant's weights as they are; the unbiased one's halves
            Nw = N * (p["w"] / (dr.weight if len(self.dirs) == 1 else 1.0))[:, None]
            blocks.append(
                np.stack(
                    [
                        Nw.ravel(),
                        (Nw * paired[:, None]).ravel(),
                        *((Nw * c[:, None]).ravel() for c in columns[k]),
                    ],
                    axis=1,
                )
            )
            blocks[-1] = (nodes.ravel(), blocks[-1])
        nodes = np.concatenate([b[0] for b in blocks])
        data = np.concatenate([b[1] for b in blocks])
        sums = self.layout.node_sum(nodes, data, 2 + len(columns[0]))
        on = (sums[:, 0] > 0.0) & (sums[:, 1] > 0.5 * sums[:, 0])
        return on, sums[on]

    def nodal(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Owned slave nodes: (global node, weight D_j, pressure p_j, gap g_j), the
        quadrature values of both directions lumped to the nodes of the first direction's
        slave surface (:meth:`_lumped`)."""
        on, sums = self._lumped(
            [[s[0], np.where(np.isfinite(s[1]), s[1], 0.0)] for s in self.state]
        )
        D = sums[:, 0]
        return np.flatnonzero(on) + self.layout.start, D, sums[:, 2] / D, sums[:, 3] / sums[:, 1]

    def nodal_normals(self) -> np.ndarray:
        """The unit normal of each node of :meth:`nodal`: the contact normal of the Gauss
        points (the one their traction -P n acts along) lumped like the pressure (weights
        N_j w; the unbiased variant's second direction with its normal reversed, the first
        direction's slave normal), normalised."""
        columns = [
            [(1.0 if k == 0 else -1.0) * p["n"][:, i] for i in range(p["n"].shape[1])]
            for k, p in enumerate(self.points)
        ]
        _, sums = self._lumped(columns)
        mean = sums[:, 2:]
        return mean / np.linalg.norm(mean, axis=1)[:, None]

    def nodal_friction(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per node of :meth:`nodal`: |t_T|, |slip increment of the step| and the stick
        indicator (the fraction of the node's support in stick), lumped like the pressure."""
        columns = []
        for P, _, t, stick, slip in self.state:
            assert t is not None and stick is not None and slip is not None  # with friction
            closed_stick = (stick & (P > 0.0)).astype(float)
            columns.append([np.linalg.norm(t, axis=1), np.linalg.norm(slip, axis=1), closed_stick])
        _, sums = self._lumped(columns)
        D = sums[:, 0]
        return sums[:, 2] / D, sums[:, 3] / D, sums[:, 4] / D > 0.5

    def slave_force(self) -> np.ndarray:
        """The force vector of the pair on the (first direction's) slave body: the quadrature
        sum of its traction -P n + t_T (minus that on the other body for the unbiased
        variant). Collective."""
        from mpi4py import MPI

        total = np.zeros(self.layout.gdim)
        for k, (p, s) in enumerate(zip(self.points, self.state, strict=True)):
            traction = -s[0][:, None] * p["n"]
            if s[2] is not None:
                traction += s[2]
            total += (1.0 if k == 0 else -1.0) * np.sum(p["w"][:, None] * traction, axis=0)
        return self.comm.allreduce(total, op=MPI.SUM)

    def force_parts(self) -> tuple[np.ndarray, np.ndarray]:
        """The normal and tangential parts of :meth:`slave_force` (whose sum they are to
        round-off): the quadrature sums of -P n and of t_T (zero without friction).
        Collective."""
        from mpi4py import MPI

        total = np.zeros((2, self.layout.gdim))
        for k, (p, s) in enumerate(zip(self.points, self.state, strict=True)):
            sign = 1.0 if k == 0 else -1.0
            total[0] += sign * np.sum(p["w"][:, None] * (-s[0][:, None] * p["n"]), axis=0)
            if s[2] is not None:
                total[1] += sign * np.sum(p["w"][:, None] * s[2], axis=0)
        total = self.comm.allreduce(total, op=MPI.SUM)
        return total[0], total[1]

    def friction_state(self) -> dict[str, float]:
        """Sums over this rank's points of the first direction (weights without the unbiased
        halving): the contact measure (P > 0), the stick measure, the friction bound mu P and
        the excess of |t_T| over it, and the sum of |t_T|."""
        p, s = self.points[0], self.state[0]
        P, t, stick = s[0], s[2], s[3]
        assert t is not None and stick is not None  # with friction
        w = p["w"] / self.dirs[0].weight
        closed = P > 0.0
        if self.mu is not None:
            bound = self.mu * P
        else:
            assert self.threshold is not None  # with friction: Coulomb or Tresca
            bound = np.where(closed, self.threshold, 0.0)
        excess = np.maximum(np.linalg.norm(t, axis=1) - bound, 0.0)
        return {
            "measure": float(np.sum(w[closed])),
            "stick": float(np.sum(w[closed & stick])),
            "bound": float(np.sum(w * bound)),
            "excess": float(np.sum(w * excess)),
            "tangential": float(np.sum(w * np.linalg.norm(t, axis=1))),
        }

    def friction_work(self) -> float:
        """Friction's dissipation on the last step, -sum_p w_p t_p . s_p over the Gauss points
        of both directions (t the slave's tangential traction, s its slip increment of the
        step relative to the master, both at the last residual: the converged state), the
        pair's counterpart of the obstacle's -int t_T . du_T ds. Collective."""
        from mpi4py import MPI

        local = 0.0
        for p, s in zip(self.points, self.state, strict=True):
            t, slip = s[2], s[4]
            assert t is not None and slip is not None  # with friction
            local -= float(np.sum(p["w"] * np.einsum("pg,pg->p", t, slip)))
        return self.comm.allreduce(local, op=MPI.SUM)

    def force(self) -> float:
        """The normal contact force (the quadrature sum of P over both directions)."""
        local = sum(
            float(np.sum(p["w"] * s[0])) for p, s in zip(self.points, self.state, strict=True)
        )
        from mpi4py import MPI

        return self.comm.allreduce(local, op=MPI.SUM)
