"""run.json's warnings on a contact zone (:func:`contactfx.results.zone_messages`) on a slave
surface of 20 segments: a closed set that reaches the surface's end, one whose edge lies on
coarse facets, and one broken into pieces by open nodes."""

from __future__ import annotations

import numpy as np

from contactfx.results import PIECES, closed_pieces, zone_messages

N = 20
NODES = np.stack([np.arange(N), np.arange(1, N + 1)], axis=1)  # a line of 21 nodes


def _facets(closed_nodes, sizes=None):
    flags = np.isin(NODES, closed_nodes)
    rim = np.isin(NODES, [0, N])
    size = np.full(N, 0.1) if sizes is None else sizes
    return NODES, flags, rim, size


def test_a_centred_zone_on_a_fine_mesh_warns_nothing():
    assert zone_messages(*_facets(np.arange(5, 15))) == []
    assert closed_pieces(NODES, np.isin(NODES, np.arange(5, 15))) == 1


def test_the_zone_at_the_surface_end():
    (line,) = zone_messages(*_facets(np.arange(0, 8)))
    assert line.startswith("the contact zone reaches the end of the slave surface")


def test_the_zone_edge_on_coarse_facets():
    sizes = np.where(np.arange(N) < 7, 0.1, 0.3)  # refined on the first 7 facets only
    (line,) = zone_messages(*_facets(np.arange(2, 10), sizes))
    # the edge facet [9, 10] is 3 times the finest closed one
    assert "edge lies on facets 3 times the finest it covers" in line
    # an edge still inside the refined region: nothing
    assert zone_messages(*_facets(np.arange(2, 6), sizes)) == []


def test_a_closed_set_in_pieces():
    every_third = np.arange(2, 19, 3)  # 6 isolated closed nodes: 6 pieces
    assert closed_pieces(NODES, np.isin(NODES, every_third)) == 6
    (line,) = zone_messages(*_facets(every_third))
    assert "breaks into 6 pieces" in line and 'smoothing = "normals"' in line
    # two zones each with one node left open: 4 pieces, under PIECES
    four = np.setdiff1d(np.r_[2:8, 12:18], [4, 15])
    assert closed_pieces(NODES, np.isin(NODES, four)) == 4 < PIECES
    assert zone_messages(*_facets(four)) == []


def test_pieces_of_triangles():
    # two triangles sharing the edge (1, 2) and a third apart: closed 0, 1, 2 and 5
    nodes = np.array([[0, 1, 2], [1, 3, 2], [4, 5, 6]])
    closed = np.isin(nodes, [0, 1, 2, 5])
    assert closed_pieces(nodes, closed) == 2
