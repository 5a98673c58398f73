"""Helpers shared by the scene definitions."""

from __future__ import annotations

import functools

import dolfinx
import numpy as np
from mpi4py import MPI

from contactfx import _compat
from contactfx.meshes import build

__all__ = [
    "gmsh_mesh",
    "fix",
    "fix_component",
    "prescribe_component",
    "reaction_forces",
]


def gmsh_mesh(comm, builder, gdim: int, name: str, **kwargs):
    """(mesh, facet_tags) of a gmsh builder from :mod:`contactfx.meshes`."""
    data = build(comm, functools.partial(builder, **kwargs), gdim, name)
    return data.mesh, data.facet_tags


def _facets(facet_tags, tag: int) -> np.ndarray:
    return facet_tags.indices[facet_tags.values == tag]


#: a contact force below this fraction of a scene's force scale counts as open: a multiplier
#: (al-ssn's, mortar's) vanishes only to Newton's tolerance where the contact has opened
OPEN_FORCE = 1e-6


def fix(V, facet_tags, tag: int):
    """u = 0 on the facets tagged ``tag`` (one condition per component, so that V may be the
    displacement part of a mixed space)."""
    if V.num_sub_spaces == 0:  # a one-component space (1D on dolfinx 0.9) has no sub-spaces
        mesh = V.mesh
        facets = _facets(facet_tags, tag)
        if V.component():  # the displacement part of a mixed space: a zero of its collapse
            collapsed, _ = V.collapse()
            dofs = _compat.locate_dofs_topological((V, collapsed), mesh.topology.dim - 1, facets)
            return [_compat.dirichletbc(dolfinx.fem.Function(collapsed), dofs, V)]
        dofs = _compat.locate_dofs_topological(V, mesh.topology.dim - 1, facets)
        return [_compat.dirichletbc(np.zeros(mesh.geometry.dim), dofs, V)]
    return [fix_component(V, facet_tags, tag, i) for i in range(V.mesh.geometry.dim)]


def fix_component(V, facet_tags, tag: int, component: int):
    """u_component = 0 on the facets tagged ``tag`` (symmetry plane or roller)."""
    mesh = V.mesh
    sub = V.sub(component)
    dofs = _compat.locate_dofs_topological(sub, mesh.topology.dim - 1, _facets(facet_tags, tag))
    return _compat.dirichletbc(np.float64(0.0), dofs, sub)


def prescribe_component(V, facet_tags, tag: int, component: int, value):
    """u_component = value (a ``dolfinx.fem.Constant`` that the load program updates) on the
    facets tagged ``tag``."""
    sub = V.sub(component)
    dofs = _compat.locate_dofs_topological(sub, V.mesh.topology.dim - 1, _facets(facet_tags, tag))
    return _compat.dirichletbc(value, dofs, sub)


def reaction_forces(V, facet_tags, tags: dict, reactions, scale=1.0) -> dict:
    """The force the supports exert on the body on each group of facets: ``tags`` maps a name
    to a facet tag, ``reactions`` is ``solver.reactions()`` (R(u) + F_c(u), nonzero on the
    supported rows at a solution); each group's reaction is the sum of its owned rows, per
    component, times ``scale`` (a number or one factor per component: the full model's force,
    ``Scene.force_symmetry``).
    Collective; returns {name: array (components,)}. A node shared by two groups counts in both."""
    values = reactions.getArray()
    n_owned = len(values)  # the owned dofs come first in the local (unrolled) numbering
    fdim = V.mesh.topology.dim - 1
    components = max(V.num_sub_spaces, 1)
    comm = V.mesh.comm
    out = {}
    for name, tag in tags.items():
        facets = _facets(facet_tags, tag)
        total = np.zeros(components)
        for c in range(components):
            sub = V.sub(c) if V.num_sub_spaces else V
            dofs = np.asarray(_compat.locate_dofs_topological(sub, fdim, facets))
            total[c] = float(np.sum(values[dofs[dofs < n_owned]]))
        out[name] = comm.allreduce(total, op=MPI.SUM) * scale + 0.0  # no -0.0
    return out
