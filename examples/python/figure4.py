#!/usr/bin/env python3
"""The source's Figure 4 from the rotorbench package: the disc velocities at u = 1.5 V.

Table 1's parameters, from rest: the upper disc settles to a near-constant speed while the
lower disc sticks and slips on a limit cycle. The three solvers are overlaid, as the source
overlays its three codes; they agree to plotting accuracy (the agreement table of the
repository's report gives the numbers). Run from anywhere, after `pip install
./crates/rotor-py matplotlib`:

    python3 examples/python/figure4.py [figure4.png]
"""

import sys

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt  # noqa: E402

import rotorbench  # noqa: E402

U = 1.5  # V
T_END = 100.0  # s

runs = {
    "event-driven (tol 1e-10)": rotorbench.simulate("event", U, t_end=T_END),
    "switch model (tol 1e-10)": rotorbench.simulate("switch", U, t_end=T_END),
    "Moreau–Jean (h 1e-3)": rotorbench.simulate("moreau", U, t_end=T_END, h=1e-3),
}
steady = rotorbench.steady(u=U)

fig, (full, zoom) = plt.subplots(
    2, 1, figsize=(8, 6.5), constrained_layout=True, gridspec_kw={"height_ratios": [3, 2]}
)
ref = runs["event-driven (tol 1e-10)"]
period = steady["period"]
for ax in (full, zoom):
    for (name, r), style in zip(runs.items(), ["-", "--", ":"]):
        ax.plot(r["t"], r["omega_l"], style, lw=1.3, label=f"$\\dot\\theta_l$, {name}")
    ax.plot(ref["t"], ref["omega_u"], "k-", lw=1.5, label="$\\dot\\theta_u$ (all three alike)")
    ax.set_ylabel("angular velocity [rad/s]")
full.set_xlim(0.0, T_END)
full.set_title(
    f"u = {U} V, Table 1, from rest: stick-slip cycle of period {period:.4f} s "
    f"(stick {steady['stick_time']:.4f} s per period)",
    fontsize=10,
)
# The last two periods, where the three solvers' cycles lie on top of each other.
zoom.set_xlim(T_END - 2.0 * period, T_END)
zoom.set_xlabel("t [s]")
handles, labels = full.get_legend_handles_labels()
fig.legend(handles, labels, loc="outside lower center", ncol=2, fontsize=8, frameon=False)
out = sys.argv[1] if len(sys.argv) > 1 else "figure4.png"
fig.savefig(out, dpi=150)
print(f"{out}: period {steady['period']:.6f} s, omega_l max {steady['omega_l_max']:.6f} rad/s")
