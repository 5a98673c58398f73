"""First Piola stress and its derivative in NumPy, per cell, of the materials finite-strain
Nitsche's consistency term between two bodies evaluates
(:mod:`contactfx.contact.point_coupling`)."""

from __future__ import annotations

import numpy as np

__all__ = ["LINEAR", "NEO_HOOKEAN", "SVK", "STRESS_MODELS", "first_piola"]

#: the stress models of finite-strain Nitsche's consistency term (:func:`first_piola`)
LINEAR, NEO_HOOKEAN, SVK = 0, 1, 2
#: by material name
STRESS_MODELS = {"linear": LINEAR, "neo-hookean": NEO_HOOKEAN, "svk": SVK}


def first_piola(
    F: np.ndarray, model: np.ndarray, lmbda: np.ndarray, mu: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The first Piola stress P (n, g, g) and its derivative A = dP/dF (n, g, g, g, g),
    A[i, J, k, L] = dP_iJ / dF_kL, of the deformation gradients F (n, g, g) (a 2D F is the
    in-plane block of a plane-strain F3 with F33 = 1; real or complex, analytic in F so that
    complex steps pass through), by model (Holzapfel 2000, Nonlinear Solid Mechanics, 6.5;
    Bonet and Wood 2008, 6.4.3):

    * LINEAR: sigma(eps), eps = sym(F - I): P = lambda tr(eps) I + 2 mu eps,
      A = lambda I x I + mu (d_ik d_JL + d_iL d_Jk);
    * NEO_HOOKEAN (psi = mu/2 (I1 - 3 - 2 ln J) + lambda/2 (ln J)^2): P = mu (F - F^-T) +
      lambda ln J F^-T, A = mu d_ik d_JL + (mu - lambda ln J) Fi_Li Fi_Jk + lambda Fi_Ji Fi_Lk
      with Fi = F^-1;
    * SVK (psi = lambda/2 (tr E)^2 + mu E : E): P = F S, S = lambda tr(E) I + 2 mu E,
      A = d_ik S_JL + lambda F_iJ F_kL + mu (F_iL F_kJ + (F F^T)_ik d_JL)."""
    g = F.shape[1]
    eye = np.eye(g)
    dd = np.einsum("ik,JL->iJkL", eye, eye)[None]  # d_ik d_JL
    lm, m = lmbda[:, None, None], mu[:, None, None]
    lm4, m4 = lm[..., None, None], m[..., None, None]
    P = np.zeros(F.shape, dtype=F.dtype)
    A = np.zeros((*F.shape, g, g), dtype=F.dtype)
    lin = model == LINEAR
    if np.any(lin):
        eps = 0.5 * (F[lin] + np.swapaxes(F[lin], 1, 2)) - eye
        tr = np.trace(eps, axis1=1, axis2=2)[:, None, None]
        P[lin] = lm[lin] * tr * eye + 2.0 * m[lin] * eps
        A[lin] = lm4[lin] * np.einsum("iJ,kL->iJkL", eye, eye)[None] + m4[lin] * (
            dd + np.einsum("iL,Jk->iJkL", eye, eye)[None]
        )
    nh = model == NEO_HOOKEAN
    if np.any(nh):
        Fn = F[nh]
        Fi = np.linalg.inv(Fn)
        FiT = np.swapaxes(Fi, 1, 2)
        lnJ = np.log(np.linalg.det(Fn))[:, None, None]
        P[nh] = m[nh] * (Fn - FiT) + lm[nh] * lnJ * FiT
        A[nh] = (
            m4[nh] * dd
            + (m4[nh] - lm4[nh] * lnJ[..., None, None]) * np.einsum("nLi,nJk->niJkL", Fi, Fi)
            + lm4[nh] * np.einsum("nJi,nLk->niJkL", Fi, Fi)
        )
    sv = model == SVK
    if np.any(sv):
        Fs = F[sv]
        E = 0.5 * (np.einsum("nki,nkj->nij", Fs, Fs) - eye)
        S = lm[sv] * np.trace(E, axis1=1, axis2=2)[:, None, None] * eye + 2.0 * m[sv] * E
        P[sv] = np.einsum("nim,nmj->nij", Fs, S)
        FFt = np.einsum("nim,nkm->nik", Fs, Fs)
        A[sv] = (
            np.einsum("ik,nJL->niJkL", eye, S)
            + lm4[sv] * np.einsum("niJ,nkL->niJkL", Fs, Fs)
            + m4[sv] * (np.einsum("niL,nkJ->niJkL", Fs, Fs) + np.einsum("nik,JL->niJkL", FFt, eye))
        )
    return P, A
