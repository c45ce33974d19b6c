"""Impossible values, gathered for the "Errors" section of report.md and ``errors``
of report.json.  Each is ``{"measure", "message"}``; the affected value itself is
an ``{"error": ...}`` in its own block and is never shown as a number.

Collected: a probe whose point is not in its part (:mod:`mpipd.post.probe_metrics`),
first-arrival times that do not increase with distance (:mod:`mpipd.post.arrivals`),
a negative energy in the rock and explosive points inside the rock
(:mod:`mpipd.post.volume`), a negative ledger term
that must be non-negative (:mod:`mpipd.post.ledger`), and any other measure that
came out as an error.
"""
from __future__ import annotations


def collect(m: dict, probes: dict) -> list[dict]:
    out = []
    for name in sorted(probes):
        if probes[name].get("error"):
            out.append({"measure": f"probe {name}", "message": probes[name]["error"]})
    ws = m["wave_speed"]
    if "error" in ws:
        out.append({"measure": "wave speed (first arrivals)", "message": ws["error"]})
    if "error" in m["energy"]:
        out.append({"measure": "energy in the rock (Fig. 20)", "message": m["energy"]["error"]})
    if "error" in m.get("gas_containment", {}):
        out.append({"measure": "gas containment", "message": m["gas_containment"]["error"]})
    out += m["energy_ledger"].get("errors", [])
    for key in ("gas_pressure", "wall_radial_stress", "wall_pressure"):
        if "error" in m[key] and not m[key]["error"].startswith("wall probe"):
            out.append({"measure": key.replace("_", " "), "message": m[key]["error"]})
    return out
