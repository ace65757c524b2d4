#!/usr/bin/env python3
"""Figures of the reference paper from the CSV files written by `kirchhoff reproduce`.

Usage: /usr/bin/python3 python/make_figures.py OUT_DIR   (reads OUT_DIR/profiles, writes OUT_DIR/figures)

Only plotting happens here: every number comes from the C++ toolkit (numeric and analytic
columns side by side in the CSV files), so no physics is re-implemented in Python.
"""
import csv
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read(path):
    return np.genfromtxt(path, delimiter=",", names=True)


def fig3(profiles, figures):
    fig, (ax, axh) = plt.subplots(1, 2, figsize=(11, 4.2))
    for path in sorted(profiles.glob("fig3_theta0_*.csv")):
        d = read(path)
        theta0 = path.stem.split("_")[-1]
        line, = ax.plot(d["x_analytic"], d["y_analytic"], "-", lw=1.2, label=f"elliptic, $\\theta_0$ = {theta0}")
        ax.plot(d["x"][::8], d["y"][::8], "o", ms=3.5, color=line.get_color(), label=f"shooting, $\\theta_0$ = {theta0}")
        axh.plot(d["s"], d["H"] - d["H"].mean(), color=line.get_color(), label=f"$\\theta_0$ = {theta0}")
    ax.set_xlabel("x / L")
    ax.set_ylabel("y / L")
    ax.set_aspect("equal")
    ax.set_title("Fig. 3: simply supported Elastica")
    ax.legend(fontsize=7, ncol=2)
    axh.set_xlabel("s / L")
    axh.set_ylabel("H(s) - mean(H)   [EI / L$^2$]")
    axh.set_title("Invariant H = EI $\\kappa^2$/2 + $n_3$ (eq. 53): flat to round-off")
    axh.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(figures / "fig3_simply_supported.png", dpi=130)
    plt.close(fig)


def fig9(profiles, figures):
    d = read(profiles / "fig9_tapered.csv")
    fig, (ax, axh) = plt.subplots(1, 2, figsize=(11, 4.2))
    ax.plot(d["x"], d["y"], "-")
    ax.set_aspect("equal")
    ax.set_xlabel("x / L")
    ax.set_ylabel("y / L")
    ax.set_title("Fig. 9: tapered Elastica, EI(s) = EI$_0$(1 + s/L)")
    axh.plot(d["s"], d["dH_ds_eq57"], "-", lw=2.5, alpha=0.5, label="eq. (57): $-\\frac{1}{2}EI'(s)\\theta'^2$")
    axh.plot(d["s"][::6], d["dH_ds_numeric"][::6], "k.", label="dH/ds of the shooting solution")
    axh.set_xlabel("s / L")
    axh.set_ylabel("dH/ds   [EI$_0$ / L$^3$]")
    axh.set_title("H is not invariant on a tapered rod")
    axh.legend()
    fig.tight_layout()
    fig.savefig(figures / "fig9_tapered.png", dpi=130)
    plt.close(fig)


def fig12(profiles, figures):
    sweep = read(profiles / "fig12_soft_wall.csv")
    fig, axes = plt.subplots(1, 4, figsize=(17, 3.8))
    ax = axes[0]
    for name, label in (("fig12_soft_wall_b1e-1.csv", "b = 0.1"), ("fig12_soft_wall_b1e-4.csv", "b = 1e-4")):
        d = read(profiles / name)
        ax.plot(d["x"], d["y"], label=label)
    half = read(profiles / "fig12_hard_wall_half.csv")
    L_minus_delta = 2 * half["x"][-1]
    ax.plot(np.concatenate([half["x"], L_minus_delta - half["x"][::-1]]), np.concatenate([half["y"], half["y"][::-1]]),
            "k--", lw=1, label="hard wall")
    ax.axhline(0.1, color="gray", lw=3, alpha=0.4)
    ax.set_xlabel("x / L")
    ax.set_ylabel("y / L")
    ax.set_title("(a) Elastica below a wall, a = 0.1, $\\Delta$ = 0.026")
    ax.legend(fontsize=8)
    ax = axes[1]
    b = sweep["b"]
    ax.loglog(b, sweep["E_wall"], "o", label="shooting")
    ax.loglog(b, sweep["E_wall"][0] * (b / b[0]) ** (2 / 3), "-", label="$\\propto b^{2/3}$")
    ax.set_xlabel("b")
    ax.set_ylabel("E$_{wall}$ (eq. 69)")
    ax.set_title("(b) interaction energy")
    ax.legend()
    for ax, name, label in ((axes[2], "fig12_soft_wall_b1e-1.csv", "(c) b = 0.1"),
                            (axes[3], "fig12_soft_wall_b1e-4.csv", "(d) b = 1e-4")):
        d = read(profiles / name)
        ax.plot(d["s"], d["H"], label="H = h - W$_{ext}$ (eq. 67)")
        ax.plot(d["s"], d["h"], label="h(s)")
        ax.axhline(-73.7, color="gray", ls=":", label="paper's hard-wall limit -73.7")
        ax.set_xlabel("s / L")
        ax.set_ylabel("[EI / L$^2$]")
        ax.set_title(label)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(figures / "fig12_soft_wall.png", dpi=120)
    plt.close(fig)


def sleeves(profiles, figures):
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 3.6))
    d = read(profiles / "fig6_sleeve.csv")
    ax.plot(d["x"], d["y"], label="outside (AB)")
    ax.plot([0, 0.6], [0, 0], "-", lw=6, color="gray", alpha=0.5, label="sleeve (BC inside)")
    ax.set_aspect("equal")
    ax.set_xlabel("x / L")
    ax.set_ylabel("y / L")
    ax.set_title("Figs. 6-7: Elastica out of a sliding sleeve, P' = P + EI $\\kappa_B^2$/2")
    ax.legend(fontsize=8)
    d = read(profiles / "fig8_arm_scale.csv")
    ax2.plot(d["x"], d["y"], label="rod outside the sleeve")
    ax2.plot([-0.4 * np.cos(0.3), 0], [-0.4 * np.sin(0.3), 0], "-", lw=6, color="gray", alpha=0.5, label="sleeve")
    ax2.plot(d["x"][-1], d["y"][-1], "v", ms=10, label="weight W (tangent horizontal)")
    ax2.set_aspect("equal")
    ax2.set_xlabel("x / L")
    ax2.set_ylabel("y / L")
    ax2.set_title("Fig. 8: the Elastica arm scale")
    ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(figures / "fig6_fig8_sleeves.png", dpi=130)
    plt.close(fig)


def plot_by_stability(ax, x, y, index, label):
    """A branch in AUTO's convention: solid where stable (index 0), dashed where unstable, dotted
    where the index is not defined (-1). Consecutive points of equal kind form one line."""
    style = {0: "-", -1: ":"}
    kinds = np.where(index > 0, 1, index).astype(int)
    start, colour, labelled = 0, None, set()
    for end in range(1, len(x) + 1):
        if end < len(x) and kinds[end] == kinds[start]:
            continue
        kind = kinds[start]
        name = {0: "stable", 1: "unstable", -1: "index undefined"}[kind]
        stop = min(end + 1, len(x))  # overlap one point so the line is unbroken
        line, = ax.plot(x[start:stop], y[start:stop], style.get(kind, "--"), lw=1.6, color=colour,
                        label=f"{label}, {name}" if name not in labelled else None)
        colour = line.get_color()
        labelled.add(name)
        start = end


def euler_branch(profiles, figures):
    d = read(profiles / "euler_buckled_branch.csv")
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(d["P_elliptic"], d["theta0"], "-", lw=3, alpha=0.4, label="elliptic integrals, 4K(k)$^2$")
    plot_by_stability(ax, d["P"], d["theta0"], d["stability_index"], "pseudo-arclength continuation")
    ax.set_xlabel("P L$^2$ / EI")
    ax.set_ylabel("$\\theta_0$ (rad)")
    ax.set_title("Fig. 3 rod: the first buckled branch (dead load)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(figures / "fig3_branch.png", dpi=130)
    plt.close(fig)


def vibrations(profiles, figures):
    d = np.genfromtxt(profiles / "vibration_column.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
    straight, buckled = d[d["branch"] == "straight"], d[d["branch"] == "buckled"]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, ks in ((axes[0], (1, 2, 3)), (axes[1], (1,))):
        for k in ks:
            rows = straight[straight["k"] == k]
            line, = ax.plot(rows["P"], rows["omega_squared_analytic"], "-", lw=1.2,
                            label=f"eq. (96), k = {k}: $EI(k\\pi)^4 - P(k\\pi)^2$")
            ax.plot(rows["P"], rows["omega_squared"], "o", ms=4, color=line.get_color(), label=f"shooting, k = {k}")
        ax.set_xlabel("P L$^2$ / EI")
        ax.set_ylabel("$\\omega_k^2$   [EI / ($\\rho S$ L$^4$)]")
    axes[1].plot(buckled["P"], buckled["omega_squared"], "s", ms=4, color="k",
                 label="buckled Elastica (dead load), k = 1")
    axes[1].axvline(np.pi ** 2, color="gray", lw=0.8, ls=":")
    axes[0].set_title("Pinned column under a dead load: $\\omega_k^2$ linear in P")
    axes[1].set_title("$\\omega_1 \\to 0$ at the Euler load, from both sides")
    for ax in axes:
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(figures / "vibration_column.png", dpi=130)
def fig5(profiles, figures):
    """Section 7.2 / Fig. 5: the Elastica in a cavity (walls y = +-a) as the end shortening grows."""
    a = 0.1  # cases/cavity.toml
    shapes = np.genfromtxt(profiles / "fig5_cavity_profiles.csv", delimiter=",", names=True, dtype=None,
                           encoding="utf-8")
    branch = np.genfromtxt(profiles / "fig5_cavity_branch.csv", delimiter=",", names=True, dtype=None,
                           encoding="utf-8")
    fig, (ax, axp) = plt.subplots(1, 2, figsize=(13, 4.4), gridspec_kw={"width_ratios": [1.5, 1]})
    deltas = sorted(set(shapes["Delta"]))
    for offset, delta in enumerate(deltas):
        rows = shapes[shapes["Delta"] == delta]
        shift = -2.6 * a * offset  # stacked, each between its own pair of walls
        for wall in (a, -a):
            ax.plot([-0.02, 1.02], [wall + shift] * 2, color="gray", lw=3, alpha=0.4)
        ax.plot(rows["x"], rows["y"] + shift, "-", lw=1.6)
        ax.text(1.04, shift, f"$\\Delta$ = {delta:.4f}\n{rows['state'][0]}", va="center", fontsize=8)
    ax.set_aspect("equal")
    ax.set_xlim(-0.05, 1.25)
    ax.set_yticks([])
    ax.set_xlabel("x / L")
    ax.set_title("Fig. 5: clamped Elastica in a cavity, walls at y = $\\pm$a (a = 0.1 L)")
    colours = {"free": "C0", "point": "C1", "flat": "C2", "fold": "C3"}
    for state, colour in colours.items():
        on = branch["state"] == state
        axp.plot(branch["Delta"][on], branch["P"][on], ".", ms=3, color=colour, label=state)
    names = (("appears", "first contact"), ("flattens", "contact flattens"),
             ("hanging fold", "flat part buckles: hanging fold"), ("lifts off", "fold contacts lift off together"))
    marked = set()
    for delta, p, label in zip(branch["Delta"], branch["P"], branch["event"]):
        name = next((short for key, short in names if key in label), None)
        if name is None or round(delta, 6) in marked:
            continue
        marked.add(round(delta, 6))  # simultaneous changes: one mark
        axp.plot(delta, p, "kx", ms=7)
        axp.annotate(name, (delta, p), textcoords="offset points", xytext=(5, 3), fontsize=7.5)
    turns = (branch["type"] == "fold") & (branch["state"] == "fold")
    axp.plot(branch["Delta"][turns], branch["P"][turns], "k^", ms=6, label="turning point (subcritical fold)")
    axp.set_xlabel("end shortening $\\Delta$ / L")
    axp.set_ylabel("P L$^2$ / EI")
    axp.set_title("load along the branch, contact events marked")
    axp.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    fig.savefig(figures / "fig5_cavity.png", dpi=130)
    plt.close(fig)


def fig11(profiles, figures):
    """Plectoneme branches: T_ext rho^2/EI against the helical angle, eq. (61) alongside.

    Reads profiles/plectoneme_<L/2R>.csv, the barrier branches (reproduce writes L/2R = 100 and 200;
    `kirchhoff plectonemes --out OUT/profiles` adds the other slendernesses), where rho is the computed
    helix radius (R plus the barrier's gap), and profiles/plectoneme_<L/2R>_ply.csv (or
    profiles/exact/..., as reproduce writes them) where present, the ply with exact contact
    (`plectonemes --hard-from`), where rho = R itself."""
    def slenderness(path):
        return int(path.stem.split("_")[1])
    barrier = sorted((p for p in profiles.glob("plectoneme_*.csv") if p.stem.split("_")[-1].isdigit()), key=slenderness)
    # reproduce writes exact plies into profiles/exact; `plectonemes --hard-from` runs written into
    # profiles itself take precedence for their slendernesses.
    exact = {slenderness(p): p for p in profiles.glob("exact/plectoneme_*_ply.csv")}
    exact.update({slenderness(p): p for p in profiles.glob("plectoneme_*_ply.csv")})
    exact = [exact[k] for k in sorted(exact)]
    if not barrier and not exact:
        return
    fig, (ax, axm) = plt.subplots(1, 2, figsize=(11, 4.2))
    theta = np.radians(np.linspace(5.0, 30.0, 200))
    eq61 = 0.5 * np.sin(theta) ** 4 * (1 + 2 / np.cos(2 * theta))
    ax.plot(np.degrees(theta), eq61, "k-", lw=1.2, label="eq. (61)")
    colours = {}
    for path, marker, what in [(p, "o", "barrier") for p in barrier] + [(p, "s", "exact contact") for p in exact]:
        d = read(path)
        ply = np.isfinite(d["eq61"]) & (d["contact_end"] - d["contact_start"] > 0.05)
        label = f"L/2R = {slenderness(path)}, {what}"
        style = dict(ms=3, color=colours.get(slenderness(path)))
        if marker == "s":
            style["mfc"] = "none"
        line, = ax.plot(np.degrees(d["helix_angle"][ply]), d["T_rho2_over_EI"][ply], marker, ls="none", label=label,
                        **style)
        colours.setdefault(slenderness(path), line.get_color())
        style["color"] = line.get_color()
        axm.plot(d["turns"][ply], d["T_rho2_over_EI"][ply] / d["eq61"][ply], marker, ls="none",
                 label=f"{label}: T (61)", **style)
        axm.plot(d["turns"][ply], np.abs(d["m3"][ply] / d["m3_eq58b"][ply]), "x", ms=3, color=line.get_color(),
                 label=f"{label}: m3 (58b)")
    ax.set_xlabel("helical angle $\\theta$ (degrees, middle of the ply)")
    ax.set_ylabel("T$_{ext}$ $\\rho^2$ / EI")
    ax.set_yscale("log")
    ax.set_xlim(5, 30)
    ax.set_title("Fig. 11: plectonemes, end pull against helical angle")
    ax.legend(fontsize=7)
    axm.axhline(1.0, color="k", lw=0.8)
    axm.set_xlabel("end rotation (turns)")
    axm.set_ylabel("numeric / helix formula")
    axm.set_title("T_ext against (61), m3 against (58b) along the branches")
    axm.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(figures / "fig11_plectonemes.png", dpi=130)
    plt.close(fig)


def wall_phase(profiles, figures):
    """The hard-wall phase diagram (reproduce --full: OUT/wall_phase/index.csv, docs/sweeps.md)."""
    path = profiles.parent / "wall_phase" / "index.csv"
    if not path.exists():
        return
    with open(path, newline="") as f:  # quoted reasons hold commas: the csv module, not genfromtxt
        rows = [r for r in csv.DictReader(f) if r["job"].startswith("arch")]
    colours = {"none": "tab:blue", "point": "tab:orange", "flat": "tab:green", "hanging_fold": "tab:red",
               "several": "tab:purple"}
    fig, ax = plt.subplots(figsize=(8, 4.4))
    for state, colour in colours.items():
        for stable, fill in ((True, colour), (False, "none")):
            pick = [r for r in rows if r["status"] == "ok" and r["contact_state"] == state
                    and (r["stability_index"] == "0") == stable]
            if pick:
                ax.scatter([float(r["Delta"]) for r in pick], [float(r["a"]) for r in pick], s=60, facecolors=fill,
                           edgecolors=colour, label=f"{state}, {'stable' if stable else 'unstable or undefined'}")
    failed = [r for r in rows if r["status"] != "ok"]
    ax.scatter([float(r["Delta"]) for r in failed], [float(r["a"]) for r in failed], marker="x", color="gray",
               label="not reached (fold, ...)")
    ax.set_xlabel("$\\Delta$ (end shortening)")
    ax.set_ylabel("a (wall height)")
    ax.set_title("Hard-wall Elastica: contact state of the arch")
    ax.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1))
    fig.tight_layout()
    fig.savefig(figures / "wall_phase_diagram.png", dpi=120)
    plt.close(fig)


def main(out):
    out = pathlib.Path(out)
    profiles, figures = out / "profiles", out / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    for make in (fig3, fig9, fig12, euler_branch, sleeves, vibrations, fig5, fig11, wall_phase):
        make(profiles, figures)
        print(f"  {make.__name__}: written", file=sys.stderr)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
