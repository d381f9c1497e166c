"""Plot a Monte Carlo of the paper's 900 s flight: RMS 3-D position error over the runs, free INS
against the KF and the adaptive KF (matplotlib).

    pip install matplotlib && python crates/ita-nav-py/examples/plot_monte_carlo.py [out.png] [runs]
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

import ita_nav

out = sys.argv[1] if len(sys.argv) > 1 else "monte_carlo.png"
runs = int(sys.argv[2]) if len(sys.argv) > 2 else 20
mc = ita_nav.monte_carlo(runs=runs)  # the paper's scenario, its master seed: cargo xtask monte-carlo's runs
fig, ax = plt.subplots(figsize=(7, 4))
for name, m in mc["modes"].items():
    ax.semilogy(mc["t_s"], m["rms_pos_3d_m"], label=f"{name} ({m['final_rms_pos_3d_m']:.1f} m at 900 s)")
ax.set_xlabel("time (s)")
ax.set_ylabel(f"RMS 3-D position error over {runs} runs (m)")
ax.legend()
ax.grid(True, which="both", alpha=0.3)
fig.savefig(out, dpi=100, bbox_inches="tight")
print(f"wrote {out}")
