"""The run's energy ledger, ``/energy/<term>`` (J, one value per frame).

Terms: mpipd.model.ledger's HELD and DISSIPATED (defined there, with what each means),
the books (initial, external, boundary: the driven points' share) and any other
dataset of /energy;
the books close as initial + external = held + dissipated, and ``balance`` is the
relative closure error (initial + external - held - dissipated) / scale.

The report reads whichever terms the file has (older files: kinetic, strain, gas,
total, external, hourglass), gives the final value of each and the largest
|balance|.  A term that must be non-negative (``mpipd.model.ledger.NON_NEGATIVE``) going
below -BALANCE_TOL (1e-3) of the ledger's scale (the largest magnitude of any J
term at any frame; the solver's own check uses the same tolerance) is an error: it
is reported as such and its values are not shown as numbers.  A ``balance`` beyond
the same bound (1e-3: healthy runs close to 2.5e-4 at the paper's geometry and to
5e-5 in blast_demo) at any frame is an error too: the books do not close.
"""
from __future__ import annotations

import numpy as np

from mpipd.model.ledger import BALANCE_TOL as TOL
from mpipd.model.ledger import DISSIPATED, HELD, NON_NEGATIVE

BOOKS = ("initial", "external", "boundary")
TERMS = HELD + DISSIPATED + BOOKS
OLD = ("strain", "total")          # the layout before the ledger
SKIP = ("t", "balance")            # not terms: the time and the closure error


def names_in(run) -> list[str]:
    """Every term of the file's /energy: TERMS and OLD in that order, then any other
    dataset (a term newer than this module) by name."""
    known = [k for k in (*TERMS, *OLD) if run.has_energy(k)]
    grp = run.f.get("energy")
    extra = sorted(k for k in (grp or {}) if k not in known and k not in SKIP) if grp else []
    return known + extra


def read(run) -> dict:
    """Collective (every rank reads the small /energy datasets): the ledger block."""
    names = names_in(run)
    if not names and not run.has_energy("balance"):
        return {"not_available": "the run file has no /energy group"}
    series = {k: np.asarray(run.energy(k), float) for k in names}
    scale = max((float(np.abs(v).max()) for v in series.values() if len(v)), default=0.0)
    errors, final = [], {}
    for k, v in series.items():
        low = int(np.argmin(v)) if len(v) else 0
        if k in NON_NEGATIVE and len(v) and v[low] < -TOL * scale:
            errors.append({"measure": f"energy ledger: {k}",
                           "message": f"{k} energy is negative ({v[low]:.4g} J at frame {low}); "
                                      "it must be >= 0"})
            final[k] = {"error": f"negative ({v[low]:.4g} J at frame {low})"}
        else:
            final[k] = float(v[-1]) if len(v) else None
    out = {"terms": [k for k in names], "final_J": final, "errors": errors,
           "layout": "ledger" if any(k in TERMS for k in names) and "strain" not in names
           else "pre-ledger (/energy/strain, /energy/total)"}
    bad = {e["measure"].split(": ")[1] for e in errors}
    out["series_J"] = {k: v.tolist() for k, v in series.items() if k not in bad}
    if run.has_energy("balance"):
        b = np.asarray(run.energy("balance"), float)
        ok = np.isfinite(b).any()
        k = int(np.nanargmax(np.abs(b))) if ok else 0
        out["balance"] = b.tolist()
        out["max_abs_balance"] = float(abs(b[k])) if ok else None
        out["max_abs_balance_frame"] = k
        first = np.flatnonzero(~(np.abs(b) <= TOL))            # beyond the bound, or NaN
        if len(first):
            f = int(first[0])
            errors.append({"measure": "energy ledger: closure",
                           "message": f"the ledger does not close: |balance| = "
                                      f"{abs(b[f]):.3g} at frame {f} (largest "
                                      f"{out['max_abs_balance']:.3g} at frame {k}), above "
                                      f"the bound {TOL:g}: energy was created or lost "
                                      "unbooked"})
    else:
        out["max_abs_balance"] = None
    return out
