"""The paper's peak-arrival speed on the direct wave for every row of the record that
stores its probes' first-pulse peak times (studies/validation/notes.md §38, §44).

mpipd.post.probe_metrics._first_pulse_peak_arrival, the function a report runs, applied
to the ``radial_stress.points`` each row's report.json holds: rows reported before the
measure existed but after §38's first-pulse peaks get the same value a report made now
would give them.  Beside it, the judged first-arrival speed.  Reads files only.

    python studies/diagnoses/peak_arrival_rows.py [studies/validation/record]
"""
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from mpipd.post.probe_metrics import _first_pulse_peak_arrival  # noqa: E402


def main():
    root = Path(sys.argv[1] if len(sys.argv) > 1 else "studies/validation/record")
    print("row  first-pulse peak speed (m/s)  R^2  first-arrival speed (m/s)  why none / left out")
    for f in sorted(root.glob("*/report.json")):
        doc = json.loads(f.read_text())
        pts = doc.get("radial_stress", {}).get("points", [])
        if not pts or "t_first_pulse_peak_us" not in pts[0]:
            continue
        fp = _first_pulse_peak_arrival(pts)
        first = doc.get("wave_speed", {}).get("speed_m_s")
        speed = f"{fp['speed_m_s']:.0f}  {fp['r2']:.4f}" if "speed_m_s" in fp else "—  —"
        why = "; ".join([fp.get("not_available", "")] + [f"{k}: {v}" for k, v in
                                                          fp.get("excluded", {}).items()])
        print(f"{f.parent.name}  {speed}  {first:.0f}  {why.strip('; ')}"
              if first is not None else f"{f.parent.name}  {speed}  —  {why.strip('; ')}")


if __name__ == "__main__":
    main()
