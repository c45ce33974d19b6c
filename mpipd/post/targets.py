"""The paper's and the experiment's numbers (DESIGN §8, paper §3.1–3.3) and the
range each run value is judged against.

Where the paper gives a range (the experiment's crack densities) that range is
used as printed.  Where it gives one number ("about 130 MPa", "n = 0.798",
"six major cracks") the band used is stated in ``band`` and printed in the
report's table next to the verdict, so the judgement can be checked.  The bands
are constants here: nothing in the analysis adapts them, or the measures, to a run.

Two rows are not bands of the paper's numbers.  The explosive's peak pressure is a
physical consistency check (``kind = "consistency"``): it must lie between the
constant-volume explosion pressure p(1, e0) and the Chapman–Jouguet pressure, both
computed from the run's own JWL constants (:mod:`mpipd.post.explosive`): the
paper's "up to 1800 MPa" (mpipd.materials.jwl.PAPER_PEAK_PRESSURE) contradicts its
Table 2 (p_CJ = 15.5 GPa), so it is shown but not judged.  The wall pressure, the
peak-arrival wave speed and the direct wave's peaks (the first pulse's, beside the
judged whole-run peaks) are information only (``kind = "information"``, verdict
"information").

The crack count and the crushed zone are judged by the paper's own measures: the
major radial cracks on Fig. 11's sections linked as lattice neighbours
(``major_radial_cracks_fig11``) and the crushed zone at first damage, the frame
nearest 4 µs of Fig. 9(a) (``crushed_zone_first_damage``).  The former rows,
``major_radial_cracks`` (end faces and mid-thickness, linked within the horizon)
and ``crushed_zone`` (last frame), are information since 2026-12; a report made
before then has them judged (``mpipd.post validate`` shows its stored verdict
beside today's).  The gas outside the copper tube (``gas_outside_tube``,
:mod:`mpipd.post.tube`) must be 0 at every frame (an intact tube holds the gas);
the gas beyond the tube's ends (venting) is information.

A value is a number, ``{"not_available": reason}`` or ``{"error": message}`` (an
impossible value: the verdict is "error: ...", and no number is shown).
"""
from __future__ import annotations

from dataclasses import dataclass

from mpipd.materials.jwl import PAPER_PEAK_PRESSURE


@dataclass(frozen=True)
class Target:
    key: str
    label: str
    unit: str
    paper: str          # what the paper's simulation reports
    experiment: str     # what the experiment reports
    lo: float | None
    hi: float | None
    band: str           # how lo..hi was derived
    kind: str = "range"     # "range", "consistency" (bounds computed per run), "information"


TARGETS = (
    Target("wave_speed", "P-wave speed from first arrivals A–G (10 % threshold)", "m/s",
           "4270 (peak arrivals)", "4535", 4270 * 0.95, 4535 * 1.05,
           "the paper's 4270 to the measured 4535, widened by 5 % each side "
           "(Table 1's c_P = 4595 lies inside)"),
    Target("wave_speed_peak", "P-wave speed from peak arrivals A–G (paper's method, Fig. 16b)",
           "m/s", "4270", "4535", None, None,
           "information only: a peak can be a reflection (first arrival is judged)",
           "information"),
    Target("wave_speed_first_pulse_peak", "P-wave speed from the first pulses' peak "
           "arrivals A–G (the paper's method on the direct wave)", "m/s", "4270", "4535",
           None, None, "information only: the first arrival is judged", "information"),
    Target("peak_sigma_rr_A", "peak radial stress at A, 6.8 mm (Fig. 16a)", "MPa",
           "≈130", "—", 130 * 0.8, 130 * 1.2, "130 ± 20 %"),
    Target("peak_sigma_rr_G", "peak radial stress at G, 59.6 mm (Fig. 16a)", "MPa",
           "< 20", "—", 0.0, 20.0, "below 20"),
    Target("attenuation_n", "attenuation exponent n of p = C d^-n (Fig. 17)", "—",
           "0.798", "agrees (Fig. 17)", 0.698, 0.898, "0.798 ± 0.1"),
    Target("peak_sigma_rr_A_first_pulse", "peak radial stress at A in its first pulse "
           "(the direct wave)", "MPa", "≈130", "—", None, None,
           "information only: the whole-run peak is judged", "information"),
    Target("attenuation_n_first_pulse", "attenuation exponent n over the first pulses' "
           "peaks A–G (the direct wave)", "—", "0.798", "agrees (Fig. 17)", None, None,
           "information only: the whole-run peaks' n is judged", "information"),
    Target("crack_density_zone1", "crack density, zone 1 (Fig. 12)", "mm/mm²",
           "slightly below experiment", "0.30–0.46", 0.30, 0.46, "experiment's range"),
    Target("crack_density_zone2", "crack density, zone 2 (Fig. 12)", "mm/mm²",
           "slightly below experiment", "0.10–0.18", 0.10, 0.18, "experiment's range"),
    Target("crack_density_zone3", "crack density, zone 3 (Fig. 12)", "mm/mm²",
           "slightly below experiment", "0.05–0.13", 0.05, 0.13, "experiment's range"),
    Target("major_radial_cracks_fig11", "major radial cracks reaching the boundary on "
           "Fig. 11's sections (z0 + 5 mm, mid-thickness, z1 − 5 mm), failed points linked "
           "as lattice neighbours (1.5 dx)", "—", "6", "several (Fig. 10)", 4, 8, "6 ± 2"),
    Target("major_radial_cracks", "major radial cracks reaching the boundary on the end "
           "faces and mid-thickness, linked within the horizon (the former count)", "—",
           "6", "several (Fig. 10)", None, None,
           "information only: the horizon-wide linking merges separate cracks; the Fig. 11 "
           "count is judged", "information"),
    Target("crushed_zone_first_damage", "crushed zone extent beyond the wall at first "
           "damage, the frame nearest 4 µs, detonation end face (Fig. 9a, §3.2)",
           "borehole radii", "≈1", "—", 0.5, 1.5, "1 ± 0.5 borehole radius"),
    Target("crushed_zone", "crushed zone extent beyond the wall at the last frame (§3.2)",
           "borehole radii", "≈1 (at first damage)", "—", None, None,
           "information only: the paper's ≈1 R_b is at first damage (judged above)",
           "information"),
    Target("ring_arc_length", "ring cracks: circumferential arcs longer than 2 horizons, "
           "total length on a section (§3.2, §3.5)", "mm",
           "minor circumferential cracks; more ring cracks in case 5", "spalling (§3.2)",
           None, None, "information only: the paper gives no number", "information"),
    Target("ring_arc_length_largest", "ring cracks: the largest over the saved frames of "
           "the total arc length on a section (the same measure at every frame)", "mm",
           "minor circumferential cracks; more ring cracks in case 5", "spalling (§3.2)",
           None, None, "information only: the paper gives no number", "information"),
    Target("ppv_radius_2p5", "distance within which PPV > 2.5 m/s (Fig. 18)", "mm",
           "≈20 (text: '2500 m/s', read as mm/s)", "—", 15.0, 25.0, "20 ± 25 %"),
    Target("peak_gas_pressure", "peak explosive pressure, every step (Fig. 7)", "MPa",
           f"up to {PAPER_PEAK_PRESSURE / 1e6:.0f}", "—", None, None,
           "physical consistency: between p(1, e0) and p_CJ of the run's JWL constants",
           "consistency"),
    Target("peak_wall_pressure", "peak −σ_rr of the rock's wall layer, every step", "MPa",
           "—", "1600 (FEM estimate)", None, None,
           "information only (Table 2 implies more than the FEM estimate)", "information"),
    Target("gas_outside_tube", "gas points outside the copper tube's current inner "
           "surface within its length, largest over the saved frames", "points",
           "— (the tube passes the load to the rock, §3.1)", "—", 0, 0,
           "0 at every frame (an intact tube holds the gas)"),
    Target("gas_beyond_tube_ends", "gas points beyond the tube's ends (venting), largest "
           "over the saved frames", "points", "—", "—", None, None,
           "information only", "information"),
    Target("P1_yields", "P1 (0.8 mm) reaches the JH2 strength (Fig. 15)", "yes/no",
           "yes, at p ≈ 200 MPa", "—", 1, 1, "yes"),
    Target("P2_yields", "P2 (1.6 mm) reaches the JH2 strength (Fig. 15)", "yes/no",
           "yes, at s ≈ 150 MPa", "—", 1, 1, "yes"),
    Target("P3_yields", "P3 (4.8 mm) reaches the JH2 strength (Fig. 15)", "yes/no",
           "no", "—", 0, 0, "no"),
)

BY_KEY = {t.key: t for t in TARGETS}


def verdict(key: str, value, bounds=None) -> str:
    """'within', 'outside', 'information', 'error: <message>' or 'not available:
    <reason>' for a value (a number, a bool, {'not_available': reason} or
    {'error': message}); ``bounds`` (lo, hi) for a consistency row."""
    if isinstance(value, dict) and "error" in value:
        return f"error: {value['error']}"
    if isinstance(value, dict) and "not_available" in value:
        return f"not available: {value['not_available']}"
    if value is None:
        return "not available"
    t = BY_KEY[key]
    if t.kind == "information":
        return "information"
    lo, hi = (t.lo, t.hi) if t.kind == "range" else (bounds or (None, None))
    if t.kind == "consistency" and bounds is None:
        return "not available: the bounds of the consistency check are not known"
    v = float(value)
    ok = (lo is None or v >= lo) and (hi is None or v <= hi)
    return "within" if ok else "outside"
