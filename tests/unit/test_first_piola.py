"""Unit test of :func:`contactfx.mechanics.piola.first_piola` (finite-strain Nitsche's
stress between two bodies): P against the complex-step derivative of each model's strain
energy written here in NumPy (independently of the function's closed forms), and A = dP/dF
against the complex-step derivative of P, in 2D (plane strain, F33 = 1) and 3D, at a
deformation with 20-40 % stretches and a rotation (Squire and Trapp 1998,
doi:10.1137/S003614459631241X: derivatives exact to round-off)."""

from __future__ import annotations

import numpy as np
import pytest

from contactfx.mechanics.piola import LINEAR, NEO_HOOKEAN, SVK, first_piola

LMBDA, MU = 577.0, 385.0


def energy(model: int, F: np.ndarray) -> complex:
    """The strain energy of a g x g F (2D: the plane-strain F3 with F33 = 1)."""
    g = F.shape[0]
    F3 = np.eye(3, dtype=F.dtype)
    F3[:g, :g] = F
    if model == LINEAR:
        eps = 0.5 * (F3 + F3.T) - np.eye(3)
        return 0.5 * LMBDA * np.trace(eps) ** 2 + MU * np.sum(eps * eps)
    if model == NEO_HOOKEAN:
        lnJ = np.log(np.linalg.det(F3))
        return 0.5 * MU * (np.trace(F3.T @ F3) - 3.0 - 2.0 * lnJ) + 0.5 * LMBDA * lnJ**2
    E = 0.5 * (F3.T @ F3 - np.eye(3))
    return 0.5 * LMBDA * np.trace(E) ** 2 + MU * np.sum(E * E)


def deformation(g: int) -> np.ndarray:
    c, s = np.cos(0.7), np.sin(0.7)
    R = np.array([[c, -s], [s, c]]) if g == 2 else np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    U = np.diag([1.3, 0.8, 1.1][:g]) + 0.1 * (np.ones((g, g)) - np.eye(g))
    return R @ U


@pytest.mark.parametrize("g", [2, 3])
@pytest.mark.parametrize("model", [LINEAR, NEO_HOOKEAN, SVK])
def test_first_piola_against_the_energy(model, g):
    F = deformation(g)
    one = np.array([model])
    lm, mu = np.array([LMBDA]), np.array([MU])
    P, A = first_piola(F[None], one, lm, mu)
    h = 1e-30
    P_ref = np.zeros((g, g))
    A_ref = np.zeros((g, g, g, g))
    for k in range(g):
        for L in range(g):
            Fc = F.astype(complex)
            Fc[k, L] += 1j * h
            P_ref[k, L] = energy(model, Fc).imag / h
            A_ref[:, :, k, L] = first_piola(Fc[None], one, lm, mu)[0][0].imag / h
    # complex steps are exact to round-off: relative 1e-13 of the largest entry
    assert np.max(np.abs(P[0] - P_ref)) < 1e-13 * np.max(np.abs(P_ref))
    assert np.max(np.abs(A[0] - A_ref)) < 1e-13 * np.max(np.abs(A_ref))
    # and A is the energy's second derivative: major symmetry A_iJkL = A_kLiJ
    assert np.max(np.abs(A[0] - A[0].transpose(2, 3, 0, 1))) < 1e-12 * np.max(np.abs(A[0]))


def test_first_piola_mixes_models():
    # a batch of cells of different models gives each its own model's values
    F = np.stack([deformation(2)] * 3)
    models = np.array([LINEAR, NEO_HOOKEAN, SVK])
    P, A = first_piola(F, models, np.full(3, LMBDA), np.full(3, MU))
    for i, m in enumerate(models):
        Pi, Ai = first_piola(F[i : i + 1], models[i : i + 1], np.array([LMBDA]), np.array([MU]))
        assert np.array_equal(P[i], Pi[0]) and np.array_equal(A[i], Ai[0]), m
