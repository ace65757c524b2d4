#!/usr/bin/env python3
"""Figures of the reference paper from the CSV files written by `kirchhoff reproduce`.

Usage: /usr/bin/python3 python/make_figures.py OUT_DIR   (reads OUT_DIR/profiles, writes OUT_DIR/figures)

Only plotting happens here: every number comes from the C++ toolkit (numeric and analytic
columns side by side in the CSV files), so no physics is re-implemented in Python.
"""
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


def main(out):
    out = pathlib.Path(out)
    profiles, figures = out / "profiles", out / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    for make in (fig3, fig9):
        make(profiles, figures)
        print(f"  {make.__name__}: written", file=sys.stderr)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
