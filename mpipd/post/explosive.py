"""The explosive's pressures implied by its own JWL constants (Table 2), beside the
run's peaks and the paper's figures (Fig. 7 and §3.1).

From the charge's material in the stored scene (:mod:`mpipd.materials.jwl`):

* p_CJ, the Chapman–Jouguet pressure (Rayleigh line tangent to the products'
  Hugoniot; 15.5 GPa for Table 2), and D_CJ;
* p(1, e0), the constant-volume explosion pressure (6.79 GPa for Table 2).

A programmed burn releases e0 in place, so the gas starts near p(1, e0) and a
steady detonation front reaches at most p_CJ: the run's peak gas pressure should
lie between the two, times the scene's ``pressure_factor`` (1 = the physics of
Table 2; another value is an explicit effective load).  That is the gas row's
consistency check.  The paper's "up to 1800 MPa" (Fig. 7) and the FEM estimate of
1600 MPa at the wall are shown beside them, as information: Table 2 itself implies
several times more, and no target here may contradict it.
"""
from __future__ import annotations

PAPER_GAS_MPA = 1800.0        # Fig. 7, "up to"
FEM_WALL_MPA = 1600.0         # §3.1, FEM estimate at the borehole wall


def reference(model, gas: dict, wall: dict) -> dict:
    m = model.explosive
    out = {"paper_gas_MPa": PAPER_GAS_MPA, "fem_wall_MPa": FEM_WALL_MPA,
           "run_peak_gas_MPa": gas.get("peak_MPa"), "run_peak_wall_sigma_rr_MPa":
           wall.get("peak_MPa"), "basis": "every step"}
    if m is None or not hasattr(m, "chapman_jouguet"):
        out["not_available"] = ("the explosive's JWL constants are not known (no jwl part in "
                                "the stored scene, or the scene does not parse)")
        return out
    cj = m.chapman_jouguet()
    pf = float(getattr(m, "pressure_factor", 1.0))
    out.update(p_CJ_MPa=cj["p"] / 1e6, D_CJ_m_s=cj["D"], V_CJ=cj["V"],
               p_constant_volume_MPa=m.pressure(1.0, m.e0) / 1e6, pressure_factor=pf)
    out["consistency_MPa"] = [pf * out["p_constant_volume_MPa"], pf * out["p_CJ_MPa"]]
    return out


def band_text(ref: dict) -> str:
    if "p_CJ_MPa" not in ref:
        return "between p(1, e0) and p_CJ of the run's JWL constants (not known)"
    pf = ref["pressure_factor"]
    lo, hi = ref["consistency_MPa"]
    scaled = "" if pf == 1.0 else f" × pressure_factor {pf:g} (an explicit effective load)"
    return (f"physical consistency: between the constant-volume explosion pressure "
            f"p(1, e0) = {ref['p_constant_volume_MPa']:.0f} MPa and p_CJ = "
            f"{ref['p_CJ_MPa']:.0f} MPa, both computed from the run's JWL constants{scaled}: "
            f"{lo:.0f}–{hi:.0f} MPa")
