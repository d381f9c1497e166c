"""Plot the position error of one simulated 900 s flight, KF against the free INS (matplotlib).

    pip install matplotlib && python crates/ita-nav-py/examples/plot_flight.py [out.png]
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import ita_nav

fig, ax = plt.subplots(figsize=(7, 4))
for name in ("standalone", "kf", "akf"):
    run = ita_nav.run_flight(filter=name, seed=1)  # the paper's scenario, one seed
    ax.semilogy(run["t_s"], np.linalg.norm(run["pos_err_ned_m"], axis=1), label=name)
ax.set_xlabel("time (s)")
ax.set_ylabel("3-D position error (m)")
ax.legend()
ax.grid(True, which="both", alpha=0.3)
out = sys.argv[1] if len(sys.argv) > 1 else "flight.png"
fig.savefig(out, dpi=100, bbox_inches="tight")
print(f"wrote {out}")
