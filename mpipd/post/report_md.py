"""``report.md``: the errors (impossible values) first, the targets table, one
section per paper figure, and what could not be computed, rendered from the same
dict as ``report.json``.  A value that is an error is printed as "error", never
as a number."""
from __future__ import annotations

from mpipd.output.writer import short_commit

from .crack_orientation import CLASSES, RING_FRACTION, rings_text


def _f(v, fmt=".3g"):
    if v is None:
        return "—"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, (int, float)):
        return format(v, fmt)
    return str(v)


def _na(block):
    return isinstance(block, dict) and "not_available" in block


def _err(block):
    return isinstance(block, dict) and "error" in block


def _why(block) -> str:
    """'not available: ...' or 'error: ...' of a block that is not a value."""
    return f"error: {block['error']}" if _err(block) else f"not available: {block['not_available']}"


def _fig(doc, name):
    if name in doc["figures"]:
        return [f"![{name}]({doc['figures'][name]})", ""]
    return [f"*Figure {name} not made: {doc['figures_not_made'].get(name, 'no data')}.*", ""]


def targets_rows(rows) -> list[str]:
    out = ["| quantity | this run | paper | experiment | range used | verdict |",
           "|---|---|---|---|---|---|"]
    for r in rows:
        v = r["value"]
        if r["verdict"].startswith("error"):
            shown = "**error**"
        elif r["unit"] == "yes/no" and v is not None:
            shown = "yes" if v else "no"
        else:
            shown = _f(v, ".4g") + (f" {r['unit']}" if v is not None and r["unit"] != "—" else "")
        if r.get("basis"):
            shown += f" ({r['basis']})"
        out.append(f"| {r['label']} | {shown} | {r['paper']} | {r['experiment']} | {r['band']} "
                   f"| **{r['verdict']}** |")
    return out


def render(doc) -> str:
    run, m = doc["run"], doc["model"]
    L = [f"# Validation report: {run['label']}", "",
         f"Run file `{run['run_file']}`: {run['n_points']} points, {doc['frames']} frames to "
         f"t = {doc['t_end_us']:.3g} µs (dt {_f(run['dt_s'])} s, {_f(run['steps'])} steps, "
         f"written by {_f(run['run_ranks'])} rank(s)); mpipd {run['mpipd_version']}, "
         f"commit {short_commit(run['git_commit'])}.",
         f"Fields: {', '.join(run['fields']) or 'none'}.  Borehole wall R_b = "
         f"{m['r_wall_m'] * 1e3:.3g} mm (rock part `{m['rock_part']}`), outer radius R_o = "
         f"{m['r_out_m'] * 1e3:.4g} mm, thickness {(m['z_m'][1] - m['z_m'][0]) * 1e3:.4g} mm, "
         f"rock dx = {m['dx_m'] * 1e3:.3g} mm.  Explosive pressure_factor: "
         f"{_f(m['pressure_factor'])} (1 = the physics of Table 2)."]
    if m["overrides"]:
        L.append("Overrides: " + ", ".join(f"`{o}`" for o in m["overrides"]) + ".")
    L += [f"Note: {n}" for n in m["notes"]]
    L += _errors(doc.get("errors", []))
    L += ["", "## Targets (paper §3.2–3.5)", "",
          "The verdict compares the run's value with the range in the 'range used' column; "
          "the ranges are fixed constants (`mpipd/post/targets.py`), not tuned to runs.  The "
          "explosive's row is a physical consistency check against its own JWL constants "
          "(Table 2); 'information' rows are shown, not judged.  Peaks are over every time "
          "step (per-point peak fields or the probes), never over the saved frames alone.", ""]
    L += targets_rows(doc["targets"])
    L += ["", "## Fracture pattern (Figs. 9, 11)", "",
          f"Times shown: {', '.join(f'{t:.3g}' for t in doc['pattern_times_us'])} µs.  Sections "
          "(z of the rock lattice level used): "
          + ", ".join(f"{k} {v:.3g} mm" for k, v in doc["sections_mm"].items()) + ".", ""]
    L += _fig(doc, "fig09_fracture_faces") + _fig(doc, "fig11_fracture_sections")
    L += ["## Failure modes (Fig. 13)", ""]
    fm = doc["failure_modes"]
    L += ["Rock points by failure mode at the last frame: " + (
        fm["not_available"] if _na(fm) else
        ", ".join(f"{k} {v}" for k, v in fm.items() if k != "note")) + ".", ""]
    L += _fig(doc, "fig13_failure_modes")
    L += _fracture(doc["fracture"]) + _fig(doc, "fig12_crack_density")
    L += _orientation(doc["fracture"])
    L += _lattice_bias(doc["lattice_bias"])
    L += (_probes(doc) + _radial(doc) + _ppv(doc) + _paths(doc) + _pressure(doc)
          + _containment(doc) + _tube(doc))
    L += _energy(doc)
    na = [f"- {r['label']}: {r['verdict'][len('not available: '):]}" for r in doc["targets"]
          if r["verdict"].startswith("not available")]
    na += [f"- figure {k}: {v}" for k, v in doc["figures_not_made"].items()]
    L += ["## Not available", ""] + (na or ["Everything was computed."]) + [""]
    return "\n".join(L) + "\n"


def _errors(errs) -> list[str]:
    L = ["", "## Errors", ""]
    if not errs:
        return L + ["None: no impossible value was found (negative energies, arrivals out of "
                    "order, probes outside their part)."]
    L += ["Impossible values: each is shown as an error below, never as a number.", ""]
    return L + [f"- **{e['measure']}**: {e['message']}" for e in errs]


def _probes(doc) -> list[str]:
    pr = doc.get("probes", {})
    if not pr:
        return []
    L = ["## Probes (recorded every step)", "",
         "Each probe samples the lattice point nearest its requested position; d is the "
         "distance from the borehole wall, requested (the scene's position) and sampled (the "
         "snapped point's); a snap of more than dx/2 of the point's part (3-D distance from "
         "the requested position) is flagged.", "",
         "| probe | d requested (mm) | d sampled (mm) | paper d (mm) | part | material | "
         "requested part | snapped (mm from the requested position) | dx/2 (mm) | check |",
         "|---|---|---|---|---|---|---|---|---|---|"]
    warn = []
    for n, p in pr.items():
        moved = p.get("moved_beyond_half_dx")
        half = None if p.get("dx_mm") is None else 0.5 * p["dx_mm"]
        L.append(f"| {n} | {_f(p.get('requested_d_mm'))} | {p['d_mm']:.3g} | "
                 f"{_f(p.get('paper_d_mm'))} | {p.get('part', '—')} | {p.get('material', '—')} | "
                 f"{p.get('requested_part') or '—'} | {_f(p.get('snap_distance_mm'))}"
                 f"{' (**> dx/2**)' if moved else ''} | {_f(half)} | "
                 f"{'**error**: ' + p['error'] if p.get('error') else 'ok'} |")
        if moved:
            warn.append(f"Warning: probe {n} was moved {p['snap_distance_mm']:.3g} mm by its snap "
                        f"(more than dx/2 = {half:.3g} mm): requested "
                        f"{_f(p.get('requested_d_mm'))} mm from the wall"
                        + (f" (paper {p['paper_d_mm']:g} mm)" if p.get("paper_d_mm") else "")
                        + f", sampled at {p['d_mm']:.3g} mm.")
    return L + [""] + (warn + [""] if warn else [])


def _fracture(fr) -> list[str]:
    L = ["## Crack density, radial cracks, crushed zone (Fig. 12, §3.2)", ""]
    if _na(fr):
        return L + [f"Not available: {fr['not_available']}.", ""]
    L += [f"Failed point: {fr['criterion']}; crack length = failed points × dx on the section; "
          "density = length / ring area; three rings of equal width from the wall to the "
          "outer boundary.", "",
          "| section | z (mm) | zone 1 | zone 2 | zone 3 | major radial cracks | crushed zone "
          "(mm beyond wall / R_b) |", "|---|---|---|---|---|---|---|"]
    for name, s in fr["sections"].items():
        z = [f"{q['density_mm_per_mm2']:.3f} ({q['failed_points']} pts)" for q in s["zones"]]
        c = s["crushed_zone"]
        L.append(f"| {name} | {s['z_mm']:.3g} | {' | '.join(z)} | {s['radial_cracks']['count']}"
                 f" | {c['extent_mm']:.3g} / {c['extent_borehole_radii']:.2f} |")
    md = fr["mean_density_mm_per_mm2"]
    L += [f"| mean | | {md[0]:.3f} | {md[1]:.3f} | {md[2]:.3f} | "
          f"{fr['major_radial_cracks']:.3g} (median) | {fr['crushed_extent_mm']:.3g} / "
          f"{fr['crushed_extent_borehole_radii']:.2f} |",
          "| experiment | | 0.30–0.46 | 0.10–0.18 | 0.05–0.13 | paper: 6 | paper: ≈ 1 R_b |", "",
          "This table's radial cracks (failed points linked within the horizon, on the end faces "
          "and mid-thickness) and crushed zone (last frame) are information; the judged count "
          "and crushed zone follow.", ""]
    L += _fig11(fr.get("fig11")) + _first_damage(fr.get("first_damage"))
    shares = [(name, s["crushed_zone"].get("mode_share")) for name, s in fr["sections"].items()]
    if any(m for _, m in shares):
        L += ["What failed the crushed zone's points (share of its failed points by the "
              "point's own failure mode; 'intact': every bond broken by its neighbours' "
              "failure): " + "; ".join(
                  f"{name}: " + ", ".join(f"{k} {v:.2f}" for k, v in m.items() if v)
                  for name, m in shares if m) + ".", ""]
    return L


def _fig11(f) -> list[str]:
    L = ["### Major radial cracks on Fig. 11's sections (the judged count)", ""]
    if f is None:
        return L + ["Not in this report (made before the Fig. 11 count).", ""]
    if _na(f):
        return L + [f"Not available: {f['not_available']}.", ""]
    L += [f"The paper counts on Fig. 11's sections: 5 mm from the detonation face, "
          f"mid-thickness, 5 mm from the far face, at the last frame.  Linking: failed points "
          f"are one crack only when they are lattice neighbours, within {f['link_dx']:g} dx "
          "(max-norm: nearest and diagonal neighbours), not within a horizon: cracks two or three "
          "spacings apart, and the late boundary damage that reaches a crack, are separate cracks "
          "on the section but lie within one horizon, which would merge them "
          "(`mpipd/post/cracks.py`).  A crack is major when it runs from zone 1 into the outer "
          "2 dx.  Headline: the median of the sections' counts.", "",
          "| Fig. 11 section | z (mm) | major radial cracks | angles (deg) | boundary arcs |",
          "|---|---|---|---|---|"]
    for name, s in f["sections"].items():
        same = f" (the level of the {s['section']})" if s["section"] != name else ""
        L.append(f"| {name}{same} | {s['z_mm']:.3g} | {s['count']} | "
                 f"{', '.join(f'{a:.0f}' for a in s['angles_deg']) or '—'} | {s['boundary_arcs']} |")
    return L + [f"| median | | {f['major_radial_cracks']:.3g} | paper: 6 | |", ""]


def _first_damage(f) -> list[str]:
    L = ["### Crushed zone at first damage (Fig. 9a, 4 µs; judged)", ""]
    if f is None:
        return L + ["Not in this report (made before the first-damage measure).", ""]
    if _na(f):
        return L + [f"Not available: {f['not_available']}.", ""]
    L += [f"The same rule as above (the unbroken run of rings of width dx from the wall with "
          f"at least 90 % of their points failed) at frame {f['frame']}, t = {f['t_us']:.3g} µs, "
          "the saved frame nearest 4 µs (Fig. 9a: \"all points within a zone of approximately "
          "one radius of the borehole are damaged\").  Judged: the detonation end face, Fig. "
          "9(a)'s view; the last frame's mean above is information.", "",
          "| section | crushed zone (mm beyond wall / R_b) |", "|---|---|"]
    for name, c in f["sections"].items():
        L.append(f"| {name} | {c['extent_mm']:.3g} / {c['extent_borehole_radii']:.2f} |")
    return L + [f"| mean | {f['mean_extent_mm']:.3g} / {f['mean_extent_borehole_radii']:.2f} |",
                "| paper (Fig. 9a) | ≈ 1 R_b |", ""]


def _orientation(fr) -> list[str]:
    L = ["## Crack orientation: radial and circumferential (§3.2, §3.5)", ""]
    if _na(fr):
        return L + [f"Not available: {fr['not_available']}.", ""]
    if not fr["sections"]:
        return L + ["Not available: no crack section.", ""]
    if not all("orientation" in s for s in fr["sections"].values()):
        return L + ["Not available: no orientation in this report (made before "
                    "mpipd/post/crack_orientation.py).", ""]
    o = next(iter(fr["sections"].values()))["orientation"]
    L += [f"Rule: {o['rule']} (`mpipd/post/crack_orientation.py`).  Crack length per class "
          "(mm, failed points × dx) in each zone; the circumferential density is its length "
          "over the ring's area, as in Fig. 12.", "",
          "| section | zone | failed points | " + " | ".join(CLASSES)
          + " | circumferential density (mm/mm²) |", "|---|---|---|" + "---|" * (len(CLASSES) + 1)]
    for name, s in fr["sections"].items():
        for z in s["orientation"]["zones"]:
            L.append(f"| {name} | {z['zone']} | {z['failed_points']} | "
                     + " | ".join(f"{z[c]['length_mm']:.4g}" for c in CLASSES)
                     + f" | {z['circumferential_density_mm_per_mm2']:.4f} |")
    L += ["", "Ring arcs: length = mean radius × the angle covered.  Failed rings: rings of "
          f"width dx beyond the crushed zone with at least {RING_FRACTION:g} of their points "
          "failed, under half of those radial, any band width.", "",
          "| section | ring arcs | total length (mm) | radii (mm) | failed rings (mm) |",
          "|---|---|---|---|---|"]
    for name, s in fr["sections"].items():
        o = s["orientation"]
        radii = ", ".join(f"{a['r_mm']:.3g}" for a in o["rings"]) or "—"
        L.append(f"| {name} | {o['ring_arcs']} | {o['ring_arc_length_mm']:.4g} | {radii} | "
                 f"{rings_text(s)} |")
    return L + [""] + _ring_history(fr.get("ring_history", {"not_available": "not computed"}))


def _ring_history(h) -> list[str]:
    L = ["Ring arcs at every saved frame (the same measure; a ring that forms and is overrun "
         "by radial damage shows only here): ring arcs / total length (mm) per section.", ""]
    if _na(h):
        return L + [f"Not available: {h['not_available']}", ""]
    names = list(h["sections"])
    L[0] += (" Arcs within each section's crushed zone at the last frame are left out (r ≤ "
             + ", ".join(f"{r:.3g}" for r in h["r_min_mm"].values()) + " mm).")
    L += ["| t (µs) | " + " | ".join(names) + " | mean length (mm) |",
          "|---|" + "---|" * (len(names) + 1)]
    for i, t in enumerate(h["t_us"]):
        cells = [f"{h['sections'][n][i]['ring_arcs']} / "
                 f"{h['sections'][n][i]['ring_arc_length_mm']:.3g}" for n in names]
        L.append(f"| {t:.3g} | " + " | ".join(cells) + f" | {h['mean_length_mm'][i]:.3g} |")
    g = h["largest"]
    return L + ["", f"Largest mean length: {g['length_mm']:.3g} mm at {g['t_us']:.3g} µs "
                f"(frame {g['frame']}).", ""]


def _lattice_bias(lb) -> list[str]:
    L = ["## Lattice bias", ""]
    if _na(lb):
        return L + [f"Not available: {lb['not_available']}.", ""]
    L += [f"Ring: {lb['ring']}.  a_m = |c_m|/c_0, the m-fold Fourier amplitude of the failed "
          "fraction against the angle, with the lattice's own angular density of points "
          "subtracted (0 for an isotropic pattern; 1 for thin cracks on the axes or on the "
          "diagonals only); noise = the mean a_m of as many failed points placed regardless "
          "of angle (`mpipd/post/lattice_bias.py`).", "",
          "| section | ring (mm) | failed points | a_4 | a_8 | noise | a_4 / noise | "
          "4-fold direction (deg; 0 axes, 45 diagonals) | major radial cracks |",
          "|---|---|---|---|---|---|---|---|---|"]
    for name, s in lb.items():
        if name == "ring":
            continue
        if _na(s):
            L.append(f"| {name} | not available: {s['not_available']} | | | | | | | |")
            continue
        ratio = s["a4"] / s["noise"] if s["noise"] > 0 else None
        L.append(f"| {name} | {s['ring_mm'][0]:.3g}–{s['ring_mm'][1]:.3g} | {s['n_failed']} of "
                 f"{s['n_points']} | {s['a4']:.3f} | {s['a8']:.3f} | {s['noise']:.3f} | "
                 f"{_f(ratio, '.1f')} | {s['a4_direction_deg']:.0f} | "
                 f"{s['major_radial_cracks']} |")
    return L + [""]


def _radial(doc) -> list[str]:
    r, w = doc["radial_stress"], doc["wave_speed"]
    L = ["## Radial stress and wave speed (Figs. 16, 17)", ""]
    if _na(r):
        return L + [f"Not available: {r['not_available']}.", ""]
    first = {a["name"]: a for a in w.get("arrivals", [])}
    L += ["| probe | d (mm) | paper d (mm) | peak −σ_rr (MPa) | peak time (µs) | "
          "first arrival (µs) | peak in first pulse | first pulse's peak (MPa) at (µs) |",
          "|---|---|---|---|---|---|---|---|"]
    for p in r["points"]:
        a = first.get(p["name"])
        fp = p.get("first_pulse_peak_MPa")
        fp = ("not in this report" if fp is None else "—" if isinstance(fp, dict)
              else f"{fp:.4g} at {p['t_first_pulse_peak_us']:.4g}")
        L.append(f"| {p['name']} | {p['d_mm']:.3g} | {p['paper_d_mm']} | {p['peak_MPa']:.4g} | "
                 f"{p['t_peak_us']:.4g}{'' if p['peak_inside_record'] else ' (end of record)'} | "
                 f"{'—' if a is None else format(a['t_us'], '.4g')} | "
                 f"{'—' if a is None else _f(a['peak_in_first_pulse'])} | {fp} |")
    L += [f"| {e['name']} | **error** | | **error** | | | | |" for e in r.get("errors", [])]
    if r["missing"]:
        L += ["", f"Probes not in the run: {', '.join(r['missing'])}."]
    if r.get("excluded_from_fit"):
        L += ["", f"Left out of the fit and the wave speed (peak at the end of the record: "
              f"the wave has not passed yet): {', '.join(r['excluded_from_fit'])}."]
    f = r["fit"]
    L += ["", "Power law p = C d^-n: " + (f"not available: {f['not_available']}" if _na(f) else
          f"C = {f['C']:.4g} MPa·mm^n, n = {f['n']:.3f}, R² = {f['r2']:.3f} over "
          f"{f['n_points']} probes") + " (paper: n = 0.798).", ""]
    if "first_pulse_fit" in r:
        g, gone = r["first_pulse_fit"], r.get("excluded_from_first_pulse_fit", {})
        L += ["Over the first pulses' peaks (the direct wave; information): " + (
            f"not available: {g['not_available']}" if _na(g) else
            f"C = {g['C']:.4g} MPa·mm^n, n = {g['n']:.3f}, R² = {g['r2']:.3f} over "
            f"{g['n_points']} probes") + (
            "; without " + "; ".join(f"{k} ({v})" for k, v in gone.items()) if gone else "")
            + ".", ""]
    L += _speeds(w)
    return L + _fig(doc, "fig16a_radial_stress") + _fig(doc, "fig16b_wave_speed") \
        + _fig(doc, "fig17_peak_radial_stress")


def _speeds(w) -> list[str]:
    if _na(w) and "arrivals" not in w:
        return [f"Wave speed: not available: {w['not_available']}.", ""]
    L = [f"Wave speed from the first arrivals (threshold: {w['threshold']}; least-squares "
         "slope of d against t): " + (f"**error**: {w['error']}" if _err(w) else
                                      f"not available: {w['not_available']}" if _na(w) else
                                      f"{w['speed_m_s']:.0f} m/s (R² {w['r2']:.3f}, probes "
                                      f"{', '.join(w['probes'])})")
         + ".  Expected: Table 1's P-wave speed c_P = √((K + 4G/3)/ρ) = 4595 m/s; "
         "measured 4535 m/s."]
    if w.get("excluded_no_arrival"):
        L.append("No first arrival: " + "; ".join(f"{k} ({v})" for k, v in
                                                   w["excluded_no_arrival"].items()) + ".")
    pa = w.get("peak_arrival", {})
    L.append("Beside it, the paper's method (arrival time of the peak, information only): "
             + (f"not available: {pa['not_available']}" if _na(pa) else
                f"{pa['speed_m_s']:.0f} m/s (R² {pa['r2']:.3f})")
             + f" (paper 4270 m/s); {pa.get('note', '')}.")
    fp = w.get("first_pulse_peak_arrival")
    if fp is not None:
        L.append("The same method on the direct wave (arrival time of each probe's "
                 "first-pulse peak, information only): "
                 + (f"not available: {fp['not_available']}" if _na(fp) else
                    f"{fp['speed_m_s']:.0f} m/s (R² {fp['r2']:.3f}, probes "
                    f"{', '.join(fp['probes'])})")
                 + ("; left out: " + "; ".join(f"{k} ({v})" for k, v in fp["excluded"].items())
                    if fp.get("excluded") else "") + ".")
    ts = w.get("threshold_study", [])
    if ts:
        L.append("The same first-arrival speed at other fractions of each probe's first-pulse peak "
                 "(information; equal for pulses that keep their shape): " + ", ".join(
                     f"{r['fraction'] * 100:g} % " + (f"{r['speed_m_s']:.0f} m/s" if "speed_m_s" in r
                                                     else "error" if "error" in r else "n/a")
                     for r in ts) + ".")
    return L + [""]


def _ppv(doc) -> list[str]:
    p, pr, rad = doc["ppv"], doc["ppv_profile"], doc["ppv_radius"]
    L = ["## PPV (Fig. 18)", ""]
    if _na(p):
        L.append(f"From the probes: not available: {p['not_available']}.")
    else:
        L.append("Peak |v_r| at the probes: " + ", ".join(
            f"{q['name']} {q['ppv_m_s']:.3g} m/s at {q['d_mm']:.3g} mm" for q in p["points"]) + ".")
        f = p["fit"]
        L.append("Holmberg–Persson PPV = K d^-β: " + (f"not available: {f['not_available']}"
                 if _na(f) else f"K = {f['C']:.4g} m/s·mm^β, β = {f['n']:.3f}, R² {f['r2']:.3f}")
                 + " (the paper gives no value of β).")
        if p.get("excluded_from_fit"):
            L.append("Left out of the fit (peak at the end of the record): "
                     + ", ".join(p["excluded_from_fit"]) + ".")
    if not _na(pr):
        L.append("Profile: ring means of each intact rock point's peak speed |v| over every step "
                 "(`peak_speed`).")
    else:
        L.append(f"Profile over the rock: not available: {pr['not_available']}.")
    L.append("Distance within which PPV > 2.5 m/s: " + (
        f"not available: {rad['not_available']}" if _na(rad) else
        f"{rad['value_mm']:.3g} mm ({rad['source']})") + " (paper: about 20 mm; the paper's "
        "'2500 m/s' read as 2500 mm/s).")
    return L + [""] + _fig(doc, "fig18_ppv")


def _paths(doc) -> list[str]:
    ps = doc["pressure_stress"]
    L = ["## Pressure–stress paths (Fig. 15)", ""]
    if _na(ps):
        return L + [f"Not available: {ps['not_available']}.", ""]
    L += ["| probe | d (mm) | peak p (MPa) | peak s (MPa) | yields | p, s at yield (MPa) | "
          "failed at (µs) |", "|---|---|---|---|---|---|---|"]
    for q in ps["points"]:
        at = "—" if not q["yielded"] else f"{q['p_at_yield_MPa']:.4g}, {q['s_at_yield_MPa']:.4g}"
        L.append(f"| {q['name']} | {q['d_mm']:.3g} | {q['peak_p_MPa']:.4g} | "
                 f"{q['peak_s_MPa']:.4g} | {_f(q['yielded'])} | {at} | {_f(q['failed_at_us'])} |")
    L += ["", "Paper: P1 yields at p ≈ 200 MPa, P2 at s ≈ 150 MPa, P3 never reaches its "
          "strength.", ""]
    return L + _fig(doc, "fig15_pressure_stress")


def _pressure(doc) -> list[str]:
    g, w, ws = doc["gas_pressure"], doc["wall_pressure"], doc["wall_radial_stress"]
    ref = doc["explosive_reference"]
    L = ["## Explosive and borehole-wall pressure (Fig. 7)", ""]

    def val(b):
        return _why(b) if (_na(b) or _err(b)) else f"{b['peak_MPa']:.4g} MPa"
    L += ["All peaks over every step.", "",
          "| quantity | MPa | source |", "|---|---|---|",
          f"| peak explosive pressure, this run | {val(g)} | {g.get('source', '')} |",
          f"| peak −σ_rr of the rock's wall layer, this run | {val(ws)} | "
          f"{ws.get('source', '')} |",
          f"| peak mean pressure of the rock's wall layer, this run | {val(w)} | "
          f"{w.get('source', '')} |"]
    if "p_CJ_MPa" in ref:
        L += [f"| Chapman–Jouguet pressure p_CJ of the run's JWL constants | "
              f"{ref['p_CJ_MPa']:.0f} | computed (D_CJ = {ref['D_CJ_m_s']:.0f} m/s) |",
              f"| constant-volume explosion pressure p(1, e0) | "
              f"{ref['p_constant_volume_MPa']:.0f} | computed |"]
    else:
        L.append(f"| p_CJ, p(1, e0) | not available | {ref['not_available']} |")
    L += [f"| paper, explosive gas (Fig. 7) | up to {ref['paper_gas_MPa']:.0f} | reported |",
          f"| FEM estimate at the wall (§3.1) | {ref['fem_wall_MPa']:.0f} | reported |", "",
          f"Explosive pressure_factor: {_f(doc['model']['pressure_factor'])} (1 = the physics of "
          "Table 2).  The paper's 1800 MPa lies well below Table 2's own p(1, e0) and p_CJ; the "
          "gas row of the targets checks the run against those two, and the wall row is "
          "information only.", ""]
    if "layer_mean_MPa" in ws:
        L += [f"Wall layer: {ws['points']} rock points with r < R_b + dx; mean over the layer of "
              f"the per-point peak −σ_rr {ws['layer_mean_MPa']:.4g} MPa.", ""]
    return L + _fig(doc, "fig07_explosive_pressure") + _fig(doc, "fig07_pressure_plane")


def _containment(doc) -> list[str]:
    g = doc.get("gas_containment")
    if g is None or _na(g):
        return []
    n = max(g["charge_points"], 1)
    ir, ii = max(g["points_in_rock"]), max(g["points_in_intact_rock"])
    pas = g.get("passive_in_intact_rock")
    L = ["### Gas containment", "",
         f"Explosive points inside the rock's volume (cracks and crushed zone included): at "
         f"most {ir} ({100 * ir / n:.3g} % of the charge's {g['charge_points']}); inside "
         f"intact rock and acting on it: at most {ii}"
         + (f" ({g['max_at_us']:.3g} µs)" if ii else "") + "; "
         + ("the run has no `gas_force` field, so every point there counts as acting."
            if pas is None else f"passive there (no gas neighbourhood, no force): at most "
            f"{max(pas)}."), ""]
    return L


def _tube(doc) -> list[str]:
    t = doc.get("tube_containment")
    if t is None or _na(t):
        return []
    L = ["### Gas containment by the tube", "",
         f"Rule (`mpipd/post/tube.py`): {t['rule']}.  Tube(s): "
         + ", ".join(f"{n} ({g} gas points, {i} inner-layer points, {b[0]} x {b[1]} bins in "
                     "z x angle)" for n, g, i, b in zip(t["tubes"], t["gas_points"],
                                                       t["inner_layer_points"], t["bins"]))
         + ".  With an intact tube no gas point is outside it.", "",
         "| frame | t (µs) | gas points outside the tube | beyond its ends |", "|---|---|---|---|"]
    L += [f"| {k} | {tu:.3g} | {o} | {b} |"
          for k, (tu, o, b) in enumerate(zip(t["t_us"], t["outside"], t["beyond_ends"]))]
    L.append("")
    f = t["first_outside"]
    L.append("Outside the tube: none at any frame." if f is None else
             f"Outside the tube first at {f['t_us']:.3g} µs (frame {f['frame']}): {f['points']} "
             f"gas points; at most {t['max_outside']}.")
    return L + [""]


def _energy(doc) -> list[str]:
    e = doc["energy"]
    L = ["## Energy in the rock (Fig. 20)", ""]
    if _err(e):
        L += [f"**error**: {e['error']}.", ""]
    elif _na(e):
        L += [f"Not available: {e['not_available']}.", ""]
    else:
        tot = e["total_J"] or e["kinetic_J"]
        what = "Σ V (ρ|v|²/2 + elastic_energy)" if e["total_J"] else "Σ V ρ|v|²/2"
        L.append(f"Energy in the rock ({what} over the rock points): peak {max(tot):.4g} J, "
                 f"final {tot[-1]:.4g} J" + (f" — {e['note']}" if e.get("note") else "") + ".")
        L.append("")
    return L + _ledger(doc["energy_ledger"]) + _fig(doc, "fig20_rock_energy")


def _ledger(led) -> list[str]:
    L = ["### Energy ledger (`/energy`)", ""]
    if _na(led):
        return L + [f"Not available: {led['not_available']}.", ""]
    L += [f"Layout: {led['layout']}.", "", "| term | final value (J) |", "|---|---|"]
    for k, v in led["final_J"].items():
        L.append(f"| {k} | {'**error**: ' + v['error'] if _err(v) else _f(v, '.6g')} |")
    b = led.get("max_abs_balance")
    L += ["", "Largest |balance| (relative closure error of initial + external = held + "
          "dissipated): " + ("not in the file" if b is None else
                             f"{b:.3g} at frame {led['max_abs_balance_frame']}") + ".", ""]
    return L
