"""Hertz2D with a bonded top layer of another Young's modulus (stiffness contrast).

Layer thickness 0.02 (about the Hertz half-width a = 0.026 of the homogeneous block), coarse
mesh h_contact = 6e-3, Nitsche with the default numerics.
"""

import dataclasses

import pytest
from mpi4py import MPI

from contactfx.scenes import Numerics
from contactfx.scenes.hertz import Hertz2D

COARSE = dataclasses.replace(Hertz2D.Params(), h_contact=6e-3)
THICKNESS = 0.02


def _layered(layer_E: float):
    return dataclasses.replace(COARSE, layer_thickness=THICKNESS, layer_E=layer_E)


class _HomogeneousStress(Hertz2D):
    """The layered scene's mesh, but the float modulus E in the stress (no DG0 field)."""

    def modulus(self, mesh):
        return None


def test_layer_of_the_same_modulus():
    params = _layered(COARSE.E)
    layered = Hertz2D(params).run(Numerics(), verbose=False)
    same_mesh = _HomogeneousStress(params).run(Numerics(), verbose=False)
    homogeneous = Hertz2D(COARSE).run(Numerics(), verbose=False)
    # same mesh, the DG0 field equal to E everywhere: the same discrete problem up to round-off
    assert layered.force == pytest.approx(same_mesh.force, rel=1e-10)
    # the interface line changes the mesh (nodes on y = -0.02), not its size field: the forces
    # differ by the discretisation error of the mesh only; measured 2.1e-5, bound 5e-4 (ten
    # times below the 5e-3 agreement of two discretisations on one mesh in test_hertz.py)
    assert layered.force == pytest.approx(homogeneous.force, rel=5e-4)
    # one material: the Hertz reference still applies
    assert "p0" in layered.reference


def test_soft_layer_between_homogeneous_blocks():
    soft_E = COARSE.E / 1e3
    layered = Hertz2D(_layered(soft_E)).run(Numerics(), verbose=False)
    soft = Hertz2D(dataclasses.replace(COARSE, E=soft_E)).run(Numerics(), verbose=False)
    stiff = Hertz2D(COARSE).run(Numerics(), verbose=False)
    # moduli ordered pointwise (soft <= layered <= stiff) and the same admissible set order the
    # minimum energies at every depth, and with them the force of these monotone force-depth
    # curves: the soft-layered block lies between the homogeneous soft and stiff blocks
    # (measured 6.0e-4 < 7.3e-3 < 0.60)
    assert soft.force < layered.force < stiff.force
    # two materials: no closed form, no reference error reported
    assert layered.reference == {}


@pytest.mark.parametrize("contrast", [1e6, 1e-6], ids=["soft-layer", "stiff-layer"])
@pytest.mark.parametrize("theta", [1, 0, -1])
def test_extreme_contrast_converges(contrast, theta):
    params = _layered(COARSE.E / contrast)
    result = Hertz2D(params).run(Numerics(theta=theta), verbose=False)
    assert result.force > 0.0
    # gamma_N scaled by the layer's modulus: Nitsche stays consistent, the penetration is
    # far below the indentation depth (measured below 1e-3 depth on the default mesh)
    assert result.max_penetration < 1e-2 * params.depth


@pytest.mark.ranks_compare
def test_layered_serial_and_parallel_agree():
    scene = Hertz2D(_layered(COARSE.E / 1e3))
    serial = scene.run(Numerics(), comm=MPI.COMM_SELF, verbose=False)
    parallel = scene.run(Numerics(), comm=MPI.COMM_WORLD, verbose=False)
    # same mesh, same discrete problem, Newton converged to 1e-10: only round-off differs
    for key in ("force", "contact_size", "peak_pressure"):
        assert getattr(parallel, key) == pytest.approx(getattr(serial, key), rel=1e-8), key
