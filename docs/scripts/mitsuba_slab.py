#!/usr/bin/env python3
"""A medium's slab transmission by a volumetric path tracer (Mitsuba 3), to
hold dermis's random walk (src/skin/walk.rs) to: a slab of a homogeneous
medium behind a smooth dielectric boundary, the light through it for light
arriving along its normal (ballistic and scattered together, per unit
irradiance; computed by reciprocity, see slab_transmission). Each channel is
its own grey medium (volpath samples distances from one channel). Prints, per
thickness and channel, the mean over seeds and its standard error.

    pip install mitsuba
    python3 docs/scripts/mitsuba_slab.py --sigma-a 0.032 0.17 0.48 \\
        --sigma-s-prime 0.74 0.88 1.01 --ior 1.4 --thickness 0.5 1 2 5

Uses the `scalar_rgb` variant (no LLVM needed). Units: mm, mm^-1.
"""
import argparse
import math
import sys

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")


def slab_transmission(sigma_a, sigma_s, d, ior, spp, seed, half_width=500.0):
    """Light through the slab for light arriving along its normal, per unit
    irradiance, by reciprocity: the radiance leaving the slab's near side along
    its normal when a black-bodied emitter of radiance 1 fills the far side's
    hemisphere (a delta light cannot be reached through a smooth dielectric)."""
    sigma_t = sigma_a + sigma_s
    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": -1, "rr_depth": 1 << 20},
        "slab": {
            "type": "cube",
            "to_world": mi.ScalarTransform4f().scale([half_width, half_width, 0.5 * d]),
            "bsdf": {"type": "dielectric", "int_ior": ior, "ext_ior": 1.0},
            "interior": {
                "type": "homogeneous",
                "albedo": sigma_s / sigma_t,
                "sigma_t": sigma_t,
                "phase": {"type": "isotropic"},
            },
        },
        "emitter": {
            "type": "rectangle",
            # Facing +z, toward the slab, just past its far side; reflects nothing.
            "to_world": mi.ScalarTransform4f().translate([0, 0, -0.5 * d - 1e-3])
            @ mi.ScalarTransform4f().scale([100 * half_width, 100 * half_width, 1]),
            "bsdf": {"type": "diffuse", "reflectance": 0.0},
            "emitter": {"type": "area", "radiance": 1.0},
        },
        "sensor": {
            "type": "radiancemeter",
            "origin": [0, 0, 0.5 * d + 10.0],
            "direction": [0, 0, -1],
            "film": {"type": "hdrfilm", "width": 1, "height": 1,
                     "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
        },
    })
    image = mi.render(scene, spp=spp, seed=seed)
    return float(np.array(image).ravel()[0])


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sigma-a", type=float, nargs=3, required=True)
    p.add_argument("--sigma-s-prime", type=float, nargs=3, required=True)
    p.add_argument("--ior", type=float, default=1.4)
    p.add_argument("--thickness", type=float, nargs="+", default=[0.5, 1, 2, 5])
    p.add_argument("--spp", type=int, default=1 << 16)
    p.add_argument("--seeds", type=int, default=4)
    a = p.parse_args()
    if a.spp < 1 or a.seeds < 2 or a.ior < 1 or any(t <= 0 for t in a.thickness):
        sys.exit("spp >= 1, seeds >= 2, ior >= 1 and thicknesses > 0, please")
    for d in a.thickness:
        row = []
        for c in range(3):
            runs = [slab_transmission(a.sigma_a[c], a.sigma_s_prime[c], d, a.ior, a.spp, s)
                    for s in range(a.seeds)]
            mean = sum(runs) / len(runs)
            var = sum((r - mean) ** 2 for r in runs) / (len(runs) - 1)
            row.append((mean, math.sqrt(var / len(runs))))
        print(f"d {d} mm: " + "  ".join(f"{m:.5f} ± {e:.5f}" for m, e in row), flush=True)


if __name__ == "__main__":
    main()
