"""Whole-model quantities from the saved frames, in one pass over the frames (each
rank reads one frame of one field of its own slice at a time).

* Energy in the rock (Fig. 20), per frame, over the points i of every rock zone:
      E_k = sum_i V_i rho |v_i|^2 / 2,   E_e = sum_i V_i e_i,   E = E_k + E_e
  with V_i the reference volume, rho from the stored scene and e_i the
  ``elastic_energy`` field (J/m^3 of reference volume: the recoverable part, 0 for
  failed points).  Without that field only E_k is given, with a note: the
  ``stress_work`` (older ``strain_energy``) field is the total stress work, elastic
  plus plastic, and is not energy held by the rock.  Sums are formed per z level and
  added in level order (bit-identical on any number of reading ranks).  A total below
  -1e-9 of its largest magnitude is an error, not a number.
* Time histories at the saved frames (drawn in Fig. 7; never used as peaks, which
  come from :mod:`mpipd.post.peaks`): the largest -sigma_rr and mean pressure of
  the rock's wall layer (r < R_b + wall_dx) and the largest gas pressure, and the
  mean pressure of the charge points of each z level at a few frames (pressure
  along the borehole).  With the ``gas_force`` field both take only the gas points
  that act at the frame: a passive point keeps the pressure it stopped acting at.
* Failure modes (Fig. 13): rock points per failure_mode at the last frame
  (0 intact, 1 JH2 plastic, 2 JH2 tensile, 3 tension model).
* Gas containment, per frame, from the ``u`` field: the explosive's points whose
  current position lies inside the rock, R_b + wall_dx/2 < r < R_o and z0 < z < z1
  (more than half a rock spacing beyond the borehole wall, within the specimen),
  and of those the ones **inside intact rock**: their nearest rock point (current
  positions) is within sqrt(3)/2 of its dx, a lattice cell's half-diagonal, and is
  intact: not one of its bonds is broken (damage 0).  A point with a broken bond
  borders a crack (a face of one planar crack has damage of about 0.3-0.45: it loses
  the bonds across the plane), and gas may enter the rock through its cracks and
  crushed zone, but not intact rock: there it has passed through the tube and the
  wall.  With the ``gas_force`` field (1 where a gas point carried a force at the
  step: mpipd.kernels.ul.well_posed), the points in intact rock are split into those
  that act on it and the passive ones, lone points with no gas neighbourhood that
  carry no force and coast; without it every point counts as acting.  Any acting
  point in intact rock makes the block an error naming the largest count and
  fraction of the charge; passive ones are counted beside it.
* Gas containment by the tube, per frame (:mod:`mpipd.post.tube`): the gas points
  outside the copper tube's current inner surface within its length, and those
  beyond its ends.  Absent (not available) without a tube holding a charge or
  without the ``u`` field.
"""
from __future__ import annotations

import numpy as np

from mpipd.kernels.layout import MODE_LABELS, N_MODES

from . import tube

NEGATIVE_TOL = 1e-9          # relative: a rock energy below -tol * max |E| is an error


def scan(run, model, profile_frames) -> dict:
    x = run.geometry("x")
    pid = run.geometry("part")
    mat = run.geometry("material")
    vol = run.geometry("volume")
    rock = model.is_rock(pid)
    r = model.radius(x)
    c, s = (x[:, 0] - model.center[0]) / np.maximum(r, 1e-300), \
        (x[:, 1] - model.center[1]) / np.maximum(r, 1e-300)
    rho = np.array([model.density.get(int(m), np.nan) for m in range(int(mat.max()) + 1)]
                   )[mat] if len(mat) else np.zeros(0)
    has_v, has_e = run.has_field("v"), run.has_field("elastic_energy")
    has_p = run.has_field("pressure")
    rock_rho_known = bool(run.min(float(np.all(np.isfinite(rho[rock]))) if len(rho) else 1.0))
    nf = run.frames
    ek = np.zeros((len(run.levels), nf))
    ee = np.zeros((len(run.levels), nf))
    wall = rock & (r < model.r_wall + model.wall_dx)
    charge = (pid == model.charge) if model.charge is not None else np.zeros(len(x), bool)
    wall_p = np.full(nf, -np.inf)
    wall_s = np.full(nf, -np.inf)
    has_s = run.has_field("stress")
    iw = np.flatnonzero(wall)
    gas_p = np.full(nf, -np.inf)
    gas = np.isin(mat, [m for m, name in enumerate(model.material_names)
                        if name in model.explosive_materials])
    has_u = run.has_field("u") and bool(run.sum_int(int(gas.sum())))
    ig = np.flatnonzero(gas)
    in_rock = np.zeros(nf, np.int64)
    in_intact = np.zeros(nf, np.int64)
    passive = np.zeros(nf, np.int64)
    has_force = run.has_field("gas_force")
    zdx = np.zeros(int(pid.max()) + 1 if len(pid) else 1)
    for q in model.zone_ids:
        if q < len(zdx):
            zdx[q] = model.dx_of(q)
    h_rock = zdx[pid[rock]]
    held = (tube.Containment(run, model, x, pid)
            if run.has_field("u") and model.tubes else None)
    prof = {}
    for k in range(nf):
        u = run.field("u", k) if has_u or held is not None else None   # this rank's slice
        if has_u:
            in_rock[k], in_intact[k], passive[k] = _gas_in_rock(run, model, x, u, ig, rock,
                                                                h_rock, k, has_force)
        if held is not None:
            held.frame(k, u)
        if has_v and rock_rho_known:
            v = run.field("v", k)
            ek[:, k] = run.per_level(np.where(rock, 0.5 * vol * rho * (v ** 2).sum(1), 0.0))
        if has_e:
            ee[:, k] = run.per_level(np.where(rock, vol * run.field("elastic_energy", k), 0.0))
        if has_s and len(iw):
            sg = run.field("stress", k, span=(int(iw[0]), int(iw[-1]) + 1))[iw - iw[0]]
            cw, sw = c[iw], s[iw]
            wall_s[k] = float((-(cw * cw * sg[:, 0] + sw * sw * sg[:, 1]
                                 + 2 * cw * sw * sg[:, 5])).max())
        if has_p:
            p = run.field("pressure", k)
            wall_p[k] = p[wall].max() if wall.any() else -np.inf
            acting = charge & (run.field("gas_force", k) > 0.0) if has_force else charge
            gas_p[k] = p[acting].max() if acting.any() else -np.inf
            if k in profile_frames and charge.any():
                prof[k] = np.stack([run.per_level(np.where(acting, p, 0.0)),
                                    run.per_level(acting.astype(float))], axis=1)
    out = {"time_s": run.time.tolist()}
    if not has_v:
        out["energy"] = {"not_available": "the run has no v field"}
    elif not rock_rho_known:
        out["energy"] = {"not_available": "the rock density is not in the stored scene"}
    else:
        out["energy"] = _rock_energy(run.level_total(ek),
                                     run.level_total(ee) if has_e else None,
                                     run.has_field("stress_work") or
                                     run.has_field("strain_energy"))
    # time histories at the saved frames (for the figure only)
    out["frame_series"] = {
        "wall_radial_stress_MPa": _series(run.max_array(wall_s)) if has_s else None,
        "wall_pressure_MPa": _series(run.max_array(wall_p)) if has_p else None,
        "gas_pressure_MPa": (_series(run.max_array(gas_p))
                             if has_p and model.charge is not None else None),
        "note": "largest value over the points at each saved frame: a history sampled "
                "every output.every steps, not the peak"}
    out["gas_profiles"] = []
    if has_p:
        lev_z = run.all_levels(run.level_z)
        for k in sorted(profile_frames):
            if k not in prof and model.charge is None:
                continue
            a = run.all_levels(prof.get(k, np.zeros((len(run.levels), 2))))
            ok = a[:, 1] > 0
            out["gas_profiles"].append({"frame": int(k), "t_us": float(run.time[k]) * 1e6,
                                        "z_mm": (lev_z[ok] * 1e3).tolist(),
                                        "p_MPa": (a[ok, 0] / a[ok, 1] / 1e6).tolist()})
    out["failure_modes"] = _failure_modes(run, rock)
    out["gas_containment"] = (_containment(in_rock, in_intact, run.sum_int(int(gas.sum())),
                                           run.time, passive if has_force else None,
                                           tube=bool(model.tubes))
                              if has_u else {"not_available": "no u field or no explosive"})
    out["tube_containment"] = (held.result() if held is not None else {"not_available": (
        "no tube holding a charge in the scene" if not model.tubes else "no u field")})
    return out


def _gas_in_rock(run, model, x, u, ig, rock, h_rock, k, has_force) -> tuple[int, int, int]:
    """Frame k (``u``: this rank's displacements at it): the explosive's points inside
    the rock's volume, those inside intact rock that act on it, and the passive ones
    there (module docstring); collective (every rank gets the counts)."""
    from scipy.spatial import cKDTree
    y = np.concatenate(run.comm.allgather(x[ig] + u[ig]))           # every gas point, on every rank
    acts = (np.concatenate(run.comm.allgather(run.field("gas_force", k)[ig] > 0.0))
            if has_force else np.ones(len(y), bool))
    ry = model.radius(y)
    inside = ((ry > model.r_wall + 0.5 * model.wall_dx) & (ry < model.r_out)
              & (y[:, 2] > model.z0) & (y[:, 2] < model.z1))
    yi = y[inside]
    ir = np.flatnonzero(rock)
    near = np.full(len(yi), np.inf)                     # distance / (sqrt(3)/2 h) of the
    intact = np.zeros(len(yi), bool)                    # nearest local rock point
    if len(ir) and len(yi):
        d, j = cKDTree(x[ir] + u[ir]).query(yi)
        near = d / (0.5 * np.sqrt(3.0) * h_rock[j])
        intact = (run.field("damage", k)[ir[j]] == 0.0 if run.has_field("damage")
                  else np.ones(len(yi), bool))
    # the nearest rock point over all ranks decides (ties: the lower rank)
    allnear = np.array(run.comm.allgather(near)).reshape(run.comm.Get_size(), -1)
    allint = np.array(run.comm.allgather(intact)).reshape(run.comm.Get_size(), -1)
    best = np.argmin(allnear, axis=0) if len(yi) else np.zeros(0, int)
    cols = np.arange(len(yi))
    hit = (allnear[best, cols] < 1.0) & allint[best, cols]
    act = acts[inside]
    return (int(inside.sum()), int(np.count_nonzero(hit & act)),
            int(np.count_nonzero(hit & ~act)))


def _containment(in_rock: np.ndarray, in_intact: np.ndarray, n_gas: int, times,
                 passive: np.ndarray | None = None, tube: bool = True) -> dict:
    """Per frame, the explosive's points inside the rock and inside intact rock (those
    acting on it; ``passive``: those carrying no force, when the run says which)."""
    k = int(np.argmax(in_intact))
    out = {"t_us": [float(t) * 1e6 for t in times], "points_in_rock": in_rock.tolist(),
           "points_in_intact_rock": in_intact.tolist(), "charge_points": int(n_gas),
           "passive_in_intact_rock": passive.tolist() if passive is not None else None,
           "max_fraction_in_rock": float(in_rock.max()) / max(n_gas, 1),
           "max_fraction_in_intact_rock": float(in_intact[k]) / max(n_gas, 1),
           "max_at_us": float(times[k]) * 1e6}
    if in_intact[k] > 0:
        out["error"] = (f"{int(in_intact[k])} explosive points "
                        f"({100 * out['max_fraction_in_intact_rock']:.3g} % of the charge) "
                        f"inside intact rock at {out['max_at_us']:.3g} us: the gas passed "
                        + ("through the tube and the borehole wall" if tube else
                           "through the borehole wall"))
    return out


def _rock_energy(kin: np.ndarray, elastic: np.ndarray | None, has_work: bool) -> dict:
    if elastic is None:
        note = ("no elastic_energy field: kinetic energy only"
                + (" (the stress_work / strain_energy field is the total stress work, "
                   "elastic + plastic, not energy held by the rock)" if has_work else ""))
        tot = kin
    else:
        note = ""
        tot = kin + elastic
    scale = float(np.abs(tot).max()) if len(tot) else 0.0
    low = int(np.argmin(tot)) if len(tot) else 0
    if len(tot) and tot[low] < -NEGATIVE_TOL * scale:
        return {"error": f"the energy in the rock is negative ({tot[low]:.4g} J at frame "
                         f"{low}): kinetic {kin[low]:.4g} J, elastic "
                         f"{'—' if elastic is None else format(elastic[low], '.4g')} J"}
    return {"kinetic_J": kin.tolist(),
            "elastic_J": None if elastic is None else elastic.tolist(),
            "total_J": None if elastic is None else tot.tolist(), "note": note}


def _series(a: np.ndarray):
    return None if not np.isfinite(a).any() else \
        (np.where(np.isfinite(a), a, np.nan) / 1e6).tolist()


def _failure_modes(run, rock) -> dict:
    nf = run.frames
    if run.has_field("failure_mode"):
        m = run.field("failure_mode", nf - 1)[rock].astype(int)
        cnt = run.sum_array(np.bincount(np.clip(m, 0, N_MODES - 1), minlength=N_MODES)
                            .astype(np.int64))
        return {MODE_LABELS[i]: int(cnt[i]) for i in range(N_MODES)}
    if "failed_points_by_mode" in run.f.attrs:
        cnt = run.f.attrs["failed_points_by_mode"]
        out = {MODE_LABELS[i]: int(cnt[i]) for i in range(N_MODES)}
        out["note"] = "whole model, from the file's failed_points_by_mode"
        return out
    return {"not_available": "no failure_mode field or attribute"}
