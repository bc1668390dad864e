#!/usr/bin/env python3
"""Diagnose a frictional-contact problem at an approximate solution: where its residual sits,
and how well its contact statuses determine the impulses.

    grainlaw solve-fc PROBLEM --tol 1e-10 --max-iterations 100000 --out sol.json
    python3 scripts/fc_active_set.py PROBLEM sol.json

PROBLEM is an fc-problem-v1 file (docs/formats.md §1, plain or gzip); sol.json is what
`solve-fc --out` writes. Needs numpy and scipy; the dense SVD limits it to a few thousand
contacts. Prints:

1. the statuses of the solution (open r_n = 0, sliding |r_t| = μ r_n, sticking) and the share of
   the squared residual of the error measure (docs/formats.md §1.2) carried by each;
2. the singular values of the active-set system A r = b that the statuses define
   (open: r = 0; sticking: u = W r + q = 0; sliding: u_n = 0 and r_t = ±μ r_n) and the
   contacts of its weakest modes;
3. the error after one correction of r towards that system, min ‖δr‖ subject to A (r + δr) = b,
   with the modes below a relative cut-off dropped (truncated SVD), for several cut-offs.

A spectral gap in 2. with the correction of 3. reaching a small error means the statuses are
right and the slow convergence comes from nearly singular modes; a correction that leaves the
cones means the statuses must change.
"""
import gzip
import json
import sys

import numpy as np
import scipy.sparse as sp


def load(path):
    with open(path, "rb") as f:
        head = f.read(2)
    opener = gzip.open if head == b"\x1f\x8b" else open
    with opener(path, "rt") as f:
        return json.load(f)


def project(rn, rt, mu):
    """Projection on the Coulomb cone |r_t| ≤ μ r_n (vectorised)."""
    out_n, out_t = rn.copy(), rt.copy()
    inside = np.abs(rt) <= mu * rn
    polar = mu * np.abs(rt) <= -rn
    side = ~inside & ~polar
    t = (rn + mu * np.abs(rt)) / (1.0 + mu * mu)
    out_n[polar], out_t[polar] = 0.0, 0.0
    out_n[side], out_t[side] = t[side], (mu * t * np.sign(rt))[side]
    return out_n, out_t


def residual(W, q, mu, r):
    """Per-contact residual of the natural map (ρ = 1) and the error measure."""
    u = W @ r + q
    rn, rt, un, ut = r[0::2], r[1::2], u[0::2], u[1::2]
    pn, pt = project(rn - (un + mu * np.abs(ut)), rt - ut, mu)
    e = np.hypot(rn - pn, rt - pt)
    scale = max(np.linalg.norm(q), np.linalg.norm(r), np.linalg.norm(u))
    return e, np.linalg.norm(e) / scale, u


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    p, s = load(sys.argv[1]), load(sys.argv[2])
    nc = p["nc"]
    n = 2 * nc
    w = p["W"]
    if w.get("storage", "coo") == "dense":
        W = sp.csr_matrix(np.array(w["data"]))
    else:
        W = sp.coo_matrix((w["val"], (w["row"], w["col"])), shape=(n, n)).tocsr()
    q, mu, r = np.array(p["q"]), np.array(p["mu"]), np.array(s["r"])
    e, err, u = residual(W, q, mu, r)
    rn, rt, ut = r[0::2], r[1::2], u[1::2]
    open_ = rn <= 1e-14 * max(rn.max(), 1e-300)
    slide = ~open_ & (np.abs(rt) >= mu * rn * (1 - 1e-9))
    stick = ~open_ & ~slide
    print(f"{nc} contacts, error {err:.3e}; |q| {np.linalg.norm(q):.3e}, |r| {np.linalg.norm(r):.3e}")
    tot = (e**2).sum()
    for name, m in (("open", open_), ("sliding", slide), ("sticking", stick)):
        share = (e[m] ** 2).sum() / tot if tot > 0 else 0.0
        print(f"  {name:8s} {m.sum():6d} contacts, {100 * share:5.1f} % of the squared residual")
    if slide.any():
        print(f"  smallest sliding speed |u_t| {np.abs(ut[slide]).min():.2e} m/s")
    # The active-set system.
    A = sp.lil_matrix((n, n))
    b = np.zeros(n)
    Wl = W.tolil()
    for a in range(nc):
        i, j = 2 * a, 2 * a + 1
        if open_[a]:
            A[i, i] = 1.0
            A[j, j] = 1.0
        else:
            A[i, :] = Wl[i, :]
            b[i] = -q[i]
            if stick[a]:
                A[j, :] = Wl[j, :]
                b[j] = -q[j]
            else:
                A[j, j] = 1.0
                A[j, i] = -mu[a] * np.sign(rt[a])
    A = A.toarray()
    U, S, Vt = np.linalg.svd(A)
    print(f"active-set system: largest singular value {S[0]:.3e}; the 12 smallest:")
    print("  " + " ".join(f"{x:.2e}" for x in S[-12:]))
    tag = np.where(open_, "open", np.where(slide, "slide", "stick"))
    for k in range(1, 7):
        v = Vt[-k]
        c = np.argsort(-np.hypot(v[0::2], v[1::2]))[:6]
        print(f"  mode σ = {S[-k]:.2e}: contacts " + ", ".join(f"{int(a)} ({tag[a]})" for a in c))
    res0 = b - A @ r
    print(f"active-set residual at r: {np.linalg.norm(res0):.3e} (|b| {np.linalg.norm(b):.3e})")
    for cut in (1e-4, 1e-6, 1e-8, 1e-10, 1e-12):
        keep = S > cut * S[0]
        dr = Vt[keep].T @ ((U[:, keep].T @ res0) / S[keep])
        x = r + dr
        _, ex, _ = residual(W, q, mu, x)
        xn, xt = x[0::2], x[1::2]
        viol = max(0.0, (np.abs(xt) - mu * xn)[~open_].max(), -xn.min())
        print(
            f"  cut-off {cut:.0e}: {keep.sum()} modes kept, |δr| {np.linalg.norm(dr):.2e}, "
            f"error {ex:.3e}, largest cone violation {viol:.2e}"
        )


if __name__ == "__main__":
    main()
