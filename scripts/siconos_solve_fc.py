#!/usr/bin/python3
"""Solve one 2D frictional-contact problem (fc-problem-v1, docs/formats.md §1) with Siconos.

    find r, u :  u = W r + q,   K_mu* ∋ u + mu|u_t| n  ⟂  r ∈ K_mu   (per contact)

This is the peer run of `grainlaw bench` (grainlaw-core/src/siconos_peer.rs, which embeds this file and feeds
it to the interpreter on stdin): Siconos numerics' `fc2d_driver` (NSGS with sparse block
storage, or Lemke's method, `fc2d_lexicolemke`) from r = 0. It is a reduced copy of the
project's earlier stand-alone Siconos driver (same reading, same problem construction, same
timing, same error), keeping only the 2D fc-problem-v1 path.

Needs Siconos 4.4 numerics' Python interface (Debian package python3-siconos, which installs
into the *system* interpreter: run it with /usr/bin/python3), numpy and scipy.

What is timed: the `fc2d_driver` call alone (not the interpreter start-up, the imports, the
reading of the file or the conversion of W to Siconos' storage), best of --repeat solves from
r = 0, stopping the repeats once the solves have taken --repeat-budget seconds in all.

The error is recomputed from the returned r with the measure of docs/formats.md §1.2 (Siconos'
`fc2d_compute_error`):
    u = W r + q,  ubar = (u_n + mu |u_t|, u_t),
    e = || r - proj_K(r - ubar) ||_2 / max(||q||, ||r||, ||u||)
"converged" is Siconos' own flag (info == 0) *and* e <= --tol.

Output: one line on stdout,
    siconos-fc-v1 solver=NAME contacts=N info=I converged=0|1 iterations=K error=E error_siconos=E seconds=S repeats=R
(iterations: Siconos' SICONOS_IPARAM_ITER_DONE; for Lemke, its pivots); with -o FILE, a JSON
file with the same figures plus "reaction" (r, contact-local, normal component first).

    /usr/bin/python3 scripts/siconos_solve_fc.py datasets/fc-problems/piles/pile_pert_100.json.gz --solver NSGS --tol 1e-6
"""
import argparse
import gzip
import json
import os
import sys
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.csc  # noqa: F401  (siconos' NM_csc conversion needs these submodules imported)
import scipy.sparse.coo  # noqa: F401

import siconos.numerics as sn


def read_json(path):
    """fc-problem-v1 (.json or .json.gz): W in COO triplets or dense rows."""
    opener = gzip.open if path.endswith(".gz") else open
    with opener(path, "rt") as f:
        d = json.load(f)
    dim, nc = int(d["dimension"]), int(d["nc"])
    if dim != 2:
        raise SystemExit("%s: dimension %d, only 2D problems are handled" % (path, dim))
    q = np.asarray(d["q"], dtype=np.float64)
    mu = np.asarray(d["mu"], dtype=np.float64)
    Wd = d["W"]
    n = dim * nc
    if Wd.get("storage", "coo") == "dense":
        W = sp.csc_matrix(np.asarray(Wd["data"], dtype=np.float64))
    else:
        W = sp.coo_matrix((np.asarray(Wd["val"], dtype=np.float64),
                           (np.asarray(Wd["row"]), np.asarray(Wd["col"]))), shape=(n, n)).tocsc()
    if W.shape != (n, n) or q.shape != (n,) or mu.shape != (nc,):
        raise SystemExit("%s: inconsistent sizes (W %s, q %s, mu %s, nc %d)" % (path, W.shape, q.shape, mu.shape, nc))
    return W, q, mu


def project_cone(xn, xt, mu):
    """Projection onto the 2D Coulomb cones {|x_t| <= mu x_n}."""
    nt = np.abs(xt)
    pn, pt = xn.copy(), xt.copy()
    zero = mu * nt <= -xn
    out = (~zero) & (nt > mu * xn)
    a = (mu * nt + xn) / (mu * mu + 1.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.where(nt > 0, mu * a / np.where(nt > 0, nt, 1.0), 0.0)
    pn[out] = a[out]
    pt[out] = s[out] * xt[out]
    pn[zero] = 0.0
    pt[zero] = 0.0
    return pn, pt


def fc_error(W, q, mu, r):
    """docs/formats.md §1.2 (= Siconos' fc2d_compute_error), recomputed from r."""
    u = W @ r + q
    rn, un, rt, ut = r[0::2], u[0::2], r[1::2], u[1::2]
    pn, pt = project_cone(rn - un - mu * np.abs(ut), rt - ut, mu)
    e = np.sqrt(np.sum((rn - pn) ** 2) + np.sum((rt - pt) ** 2))
    scale = max(np.linalg.norm(q), np.linalg.norm(r), np.linalg.norm(u))
    return e / scale if scale > np.finfo(float).eps else e


def build_problem(W, q, mu):
    """Siconos FrictionContactProblem with W in sparse block storage (what fc2d NSGS wants)."""
    nc = len(mu)
    q = np.ascontiguousarray(q, dtype=np.float64)
    mu = np.ascontiguousarray(mu, dtype=np.float64)
    Wc = sp.csc_matrix(W)
    Wc.sort_indices()
    Wc.indices = Wc.indices.astype(np.int64)
    Wc.indptr = Wc.indptr.astype(np.int64)
    info, sbm = sn.SBM_from_csparse(2, Wc)
    if info != 0:
        raise SystemExit("SBM_from_csparse failed (info=%d)" % info)
    p = sn.FrictionContactProblem()
    p.dimension = 2
    p.numberOfContacts = nc
    p.M = sbm
    p.q = q
    p.mu = mu
    return p, (Wc, sbm, q, mu)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("problem")
    ap.add_argument("--solver", default="NSGS", choices=["NSGS", "LEMKE"])
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--max-iter", type=int, default=100000)
    ap.add_argument("--repeat", type=int, default=1, help="solve up to N times from r=0, report the fastest")
    ap.add_argument("--repeat-budget", type=float, default=float("inf"),
                    help="stop repeating once the solves took this many seconds in all")
    ap.add_argument("-o", "--out", default=None, help="write JSON with the figures + reaction")
    a = ap.parse_args(argv)

    W, q, mu = read_json(a.problem)
    nc = len(mu)
    sid = getattr(sn, "SICONOS_FRICTION_2D_" + a.solver)
    best = None
    spent = 0.0
    repeats = 0
    while repeats < max(a.repeat, 1) and (repeats == 0 or spent < a.repeat_budget):
        prob, keep = build_problem(W, q, mu)
        so = sn.SolverOptions(sid)
        so.iparam[sn.SICONOS_IPARAM_MAX_ITER] = a.max_iter
        so.dparam[sn.SICONOS_DPARAM_TOL] = a.tol
        r = np.zeros(2 * nc)
        u = np.zeros(2 * nc)
        t0 = time.perf_counter()
        info = sn.fc2d_driver(prob, r, u, so)
        dt = time.perf_counter() - t0
        spent += dt
        repeats += 1
        res = dict(info=int(info), iterations=int(so.iparam[sn.SICONOS_IPARAM_ITER_DONE]),
                   error_siconos=float(so.dparam[sn.SICONOS_DPARAM_RESIDU]), seconds=dt, r=r.copy())
        if best is None or dt < best["seconds"]:
            best = res
        del prob, keep

    r = best["r"]
    err = float(fc_error(W, q, mu, r))
    converged = best["info"] == 0 and np.isfinite(err) and err <= a.tol
    print("siconos-fc-v1 solver=%s contacts=%d info=%d converged=%d iterations=%d error=%.6e "
          "error_siconos=%.6e seconds=%.6e repeats=%d"
          % (a.solver, nc, best["info"], int(converged), best["iterations"], err,
             best["error_siconos"], best["seconds"], repeats))
    sys.stdout.flush()
    if a.out:
        summary = dict(problem=os.path.basename(a.problem), solver=a.solver, contacts=nc, info=best["info"],
                       converged=bool(converged), iterations=best["iterations"], error=err,
                       error_siconos=best["error_siconos"], seconds=best["seconds"], repeats=repeats,
                       reaction=r.tolist())
        with open(a.out, "w") as f:
            json.dump(summary, f)
    return 0


if __name__ == "__main__":
    sys.exit(main())
