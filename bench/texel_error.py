#!/usr/bin/env python3
"""Where the worst texels of one mapped state sit, against the virtual rig's
apparent truth through surface correspondence (the report's |app| figures:
observed texels seen within 60 degrees). Reads build/bench_texel_error's
output and the state's derived maps; prints the median and p95 of |error|
and, for each group of texels, its share of all texels and of the worst 5 %:
by facing (the vertical axis through the surface's centre: outward, inward,
up, down), by height band (the top 15 %: rims), by distance to the edge of
its UV chart (texels within one texel of a chart's edge straddle it), by
the distance to the matched true point (surface the reconstruction made up)
and by best viewing angle. Writes OUT_DIR/worst.png: the UV map, surface
texels grey, the worst 5 % coloured by facing (outward red, inward blue,
up magenta, down yellow).
usage: bench/texel_error.py RELEASE_ROOT INSTANCE STATE OUT_DIR
(run build/bench_texel_error RELEASE_ROOT INSTANCE STATE OUT_DIR first)"""
import sys

import cv2
import numpy as np

root, inst, state, out = sys.argv[1:5]
d = f"{root}/instances/{inst}/derived/{state}/"
obs = np.load(d + "temperature_observed.npy").astype(np.float64)
mask = np.load(d + "mask.npy")
app = np.load(f"{out}/apparent.npy").astype(np.float64)
dist = np.load(f"{out}/dist.npy")
away = np.load(f"{out}/away.npy")
surf = np.load(f"{out}/surface.npy")
cond = np.load(f"{out}/conditions.npy")
R = obs.shape[0]
sel = (mask == 1) & np.isfinite(obs) & (away > 0) & np.isfinite(app)
err = np.abs(obs - app)
es = err[sel]
thr = np.quantile(es, 0.95)
worst = sel & (err >= thr)
print(f"{inst} {state}: {sel.sum()} texels, median {np.median(es):.3f} p95 {thr:.3f} degC, "
      f"signed median of the worst {np.median((obs - app)[worst]):+.3f}")

on = np.isfinite(surf[..., 0])
p, n = surf[..., :3], surf[..., 3:]
c = np.nanmean(p[on], axis=0)
rx, ry = p[..., 0] - c[0], p[..., 1] - c[1]
rl = np.maximum(np.hypot(rx, ry), 1e-9)
radial = (n[..., 0] * rx + n[..., 1] * ry) / rl
z = p[..., 2]
zlo, zhi = np.nanmin(z[on]), np.nanmax(z[on])
edge = cv2.distanceTransform(on.astype(np.uint8), cv2.DIST_L2, 3)


def row(name, g):
    g = g & sel
    if not g.any():
        return
    print(f"  {name:34s} {100 * g.sum() / sel.sum():5.1f}% of texels, "
          f"{100 * (g & worst).sum() / worst.sum():5.1f}% of the worst; "
          f"p95 {np.quantile(err[g], 0.95):.3f}")


facing = {"up (n_z > 0.7)": n[..., 2] > 0.7, "down (n_z < -0.7)": n[..., 2] < -0.7}
side = ~(facing["up (n_z > 0.7)"] | facing["down (n_z < -0.7)"])
facing["outward (radial > 0.5)"] = side & (radial > 0.5)
facing["inward (radial < -0.5)"] = side & (radial < -0.5)
facing["other"] = side & (np.abs(radial) <= 0.5)
print(" facing:")
for k, g in facing.items():
    row(k, g)
print(" height:")
top = z > zhi - 0.15 * (zhi - zlo)
row("top 15 % (rims)", top)
row("below", ~top)
print(" distance to the chart's edge in UV:")
row("<= 1 texel (straddling)", edge <= 1.1)
row("1-2 texels", (edge > 1.1) & (edge <= 2.1))
row("> 2 texels", edge > 2.1)
row("outward, below the top, <= 1 texel", facing["outward (radial > 0.5)"] & ~top & (edge <= 1.1))
row("outward, below the top, > 2 texels", facing["outward (radial > 0.5)"] & ~top & (edge > 2.1))
print(" distance to the matched true point:")
row("< 1 mm", dist < 1e-3)
row(">= 3 mm (no true surface there)", dist >= 3e-3)
print(" best viewing angle:")
row("within 37 degrees (cos > 0.8)", cond[..., 0] > 0.8)
row("37-53 degrees (cos 0.6-0.8)", (cond[..., 0] > 0.6) & (cond[..., 0] <= 0.8))

img = np.zeros((R, R, 3), np.uint8)
img[on] = (60, 60, 60)
img[sel] = (110, 110, 110)
colours = {"outward (radial > 0.5)": (0, 0, 255), "inward (radial < -0.5)": (255, 128, 0),
           "up (n_z > 0.7)": (255, 0, 255), "down (n_z < -0.7)": (0, 255, 255),
           "other": (255, 255, 255)}
for k, col in colours.items():
    img[worst & facing[k]] = col
cv2.imwrite(f"{out}/worst.png", cv2.resize(img, (3 * R, 3 * R), interpolation=cv2.INTER_NEAREST))
print(f" -> {out}/worst.png")
