#!/usr/bin/env python3
"""The scanned head as a homogeneous medium in a volumetric path tracer
(Mitsuba 3): the truth dermis's `[skin.medium]` is held to (docs/media.md).

The mesh (assets/head/lee-perry-smith/LeePerrySmith.glb, 50.3 mm per unit, in
dermis's world: mm, +Y up) is the boundary of one homogeneous medium: a rough
dielectric (Beckmann alpha = the skin's roughness m, eta = ior) around a medium
of the given sigma_a and sigma_s_prime (mm^-1; isotropic, so sigma_s =
sigma_s_prime). Each colour channel is rendered as its own grey medium
(volpath samples distances from one channel, and the others' weights diverge
over long walks). The output is one EXR in the layout
docs/scripts/cycles_compare.py reads as a reference: Combined.{R,G,B,A} (linear
radiance, alpha = coverage) and Position.{X,Y,Z} (the first surface hit, dermis
world mm).

Scenes (match dermis's with the same camera, size and lights; docs/scenes/):
  uniform   a uniform sky of radiance 1 (docs/scenes/skin1-uniform.toml)
  sun       a uniform sky of radiance 0.25 and a sun: a directional light of
            irradiance pi travelling along SUN_DIRECTION (docs/scenes/skin1-sun.toml)
  backlit   the left side of the head, lit from behind by a directional light of
            irradiance pi travelling along BACK_DIRECTION, under a sky of
            radiance 0.02 (docs/scenes/skin1-backlit.toml)

    pip install mitsuba
    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so \\
    python3 docs/scripts/mitsuba_medium.py --scene uniform --spp 256 --seed 1 \\
        --out ref-uniform-1.exr

Uses the `llvm_ad_rgb` variant (Dr.Jit's LLVM backend: on Debian 12 it needs a
newer libLLVM than the system's 15, e.g. Debian's libllvm19, through
DRJIT_LIBLLVM_PATH); `--variant scalar_rgb` works without LLVM, slowly.
Units: mm, mm^-1.
"""
import argparse
import json
import math
import os
import struct
import sys
import tempfile

import numpy as np

MM_PER_UNIT = 50.3
HERE = os.path.dirname(os.path.abspath(__file__))
GLB = os.path.join(HERE, "..", "..", "assets", "head", "lee-perry-smith", "LeePerrySmith.glb")
# Directions the lights travel (from the light into the scene), dermis world.
SUN_DIRECTION = [-0.5, -0.6, -1.0]
BACK_DIRECTION = [-0.3, -0.2, 1.0]
SCENES = {
    # camera position, target (mm), vertical field of view (deg), size, sky, lights
    "uniform": ([229, 119, 629], [0, 60, 0], 30.0, (256, 320), 1.0, []),
    "sun": ([229, 119, 629], [0, 60, 0], 30.0, (256, 320), 0.25, [(SUN_DIRECTION, math.pi)]),
    "backlit": ([-400, 65, -10], [-80, 65, -10], 30.0, (256, 320), 0.02, [(BACK_DIRECTION, math.pi)]),
}
# Jensen et al. 2001, Table 2 (skin1), mm^-1.
SKIN1 = ([0.032, 0.17, 0.48], [0.74, 0.88, 1.01])


def read_glb(path):
    """Positions (mm), normals and triangles of the glb's one primitive."""
    with open(path, "rb") as f:
        data = f.read()
    magic, _, _ = struct.unpack("<III", data[:12])
    if magic != 0x46546C67:
        raise SystemExit(f"{path}: not a glb file")
    n = struct.unpack("<I", data[12:16])[0]
    gltf = json.loads(data[20 : 20 + n])
    binary = data[20 + n + 8 :]
    prim = gltf["meshes"][0]["primitives"][0]

    def accessor(i):
        a = gltf["accessors"][i]
        view = gltf["bufferViews"][a["bufferView"]]
        dtype = {5123: np.uint16, 5125: np.uint32, 5126: np.float32}[a["componentType"]]
        width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}[a["type"]]
        start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        return np.frombuffer(binary, dtype, a["count"] * width, start).reshape(a["count"], width)

    pos = accessor(prim["attributes"]["POSITION"]).astype(np.float64) * MM_PER_UNIT
    nrm = accessor(prim["attributes"]["NORMAL"]).astype(np.float64)
    tri = accessor(prim["indices"]).reshape(-1, 3).astype(np.uint32)
    return pos, nrm, tri


def write_ply(path, pos, nrm, tri):
    """Binary little-endian PLY with vertex normals (Mitsuba's `ply` shape)."""
    head = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(pos)}\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        f"element face {len(tri)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    verts = np.hstack([pos, nrm]).astype("<f4")
    faces = np.zeros(len(tri), dtype=[("n", "u1"), ("i", "<i4", 3)])
    faces["n"] = 3
    faces["i"] = tri
    with open(path, "wb") as f:
        f.write(head.encode())
        f.write(verts.tobytes())
        f.write(faces.tobytes())


def scene_dict(mi, ply, scene, channel, args, spp, seed, aov=False):
    origin, target, fov, (w, h), sky, lights = SCENES[scene]
    if args.scale > 1:
        w, h = w // args.scale, h // args.scale
    sigma_a = args.sigma_a[channel]
    sigma_s = args.sigma_s_prime[channel] / (1.0 - args.g)
    sigma_t = sigma_a + sigma_s
    d = {
        "type": "scene",
        "integrator": (
            # A nested integrator gives the film its alpha (coverage, no emitters).
            {"type": "aov", "aovs": "pp:position", "nested": {"type": "direct"}}
            if aov
            else {"type": "volpath", "max_depth": -1, "rr_depth": 1 << 20}
        ),
        "sensor": {
            "type": "perspective",
            "fov": fov,
            "fov_axis": "y",
            "near_clip": 1.0,
            "far_clip": 10000.0,
            "to_world": mi.ScalarTransform4f().look_at(origin=origin, target=target, up=[0, 1, 0]),
            "film": {
                "type": "hdrfilm",
                "width": w,
                "height": h,
                "rfilter": {"type": "box"},
                "pixel_format": "rgba",
            },
            "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
        },
        "head": {
            "type": "ply",
            "filename": ply,
            "bsdf": {
                "type": "roughdielectric",
                "distribution": "beckmann",
                "alpha": args.roughness,
                "int_ior": args.ior,
                "ext_ior": 1.0,
            },
            "interior": {
                "type": "homogeneous",
                "albedo": sigma_s / sigma_t,
                "sigma_t": sigma_t,
                "phase": {"type": "hg", "g": args.g} if args.g else {"type": "isotropic"},
            },
        },
    }
    if aov:
        # No emitters: the film's alpha is then the mesh's coverage.
        return d
    d["sky"] = {"type": "constant", "radiance": {"type": "rgb", "value": [sky] * 3}}
    for i, (direction, irradiance) in enumerate(lights):
        d[f"light{i}"] = {
            "type": "directional",
            "direction": direction,
            "irradiance": {"type": "rgb", "value": [irradiance] * 3},
        }
    return d


def render(mi, ply, args, channel, seed):
    scene = mi.load_dict(scene_dict(mi, ply, args.scene, channel, args, args.spp, seed))
    return np.array(mi.render(scene, seed=seed))[..., 0]


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--scene", choices=sorted(SCENES), required=True)
    p.add_argument("--sigma-a", type=float, nargs=3, default=SKIN1[0])
    p.add_argument("--sigma-s-prime", type=float, nargs=3, default=SKIN1[1])
    p.add_argument("--g", type=float, default=0.0)
    p.add_argument("--ior", type=float, default=1.4)
    p.add_argument("--roughness", type=float, default=0.3, help="Beckmann alpha (the skin's m)")
    p.add_argument("--spp", type=int, default=256)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--scale", type=int, default=1,
                   help="render at 1/SCALE of the size: each pixel then averages SCALE x SCALE "
                   "of dermis's (cycles_compare.py --bins BINS/SCALE at the same bins)")
    p.add_argument("--variant", default="llvm_ad_rgb")
    p.add_argument("--out", required=True, help="the reference EXR")
    p.add_argument("--specular-only", action="store_true",
                   help="an interior that absorbs all it is given: the boundary's reflection "
                   "alone (dermis: --view specular)")
    args = p.parse_args()
    if not args.out.endswith(".exr"):
        p.error("--out must end in .exr")
    if not os.path.isdir(os.path.dirname(os.path.abspath(args.out))):
        p.error(f"no folder for {args.out}")
    if not (0 <= args.g < 1 and args.ior > 1 and args.roughness > 0 and args.spp > 0):
        p.error("need 0 <= g < 1, ior > 1, roughness > 0, spp > 0")
    if not os.path.isfile(GLB):
        p.error(f"no mesh {GLB}")

    import mitsuba as mi
    import OpenEXR

    mi.set_variant(args.variant)
    pos, nrm, tri = read_glb(GLB)
    with tempfile.TemporaryDirectory() as tmp:
        ply = os.path.join(tmp, "head.ply")
        write_ply(ply, pos, nrm, tri)
        if args.specular_only:
            # An interior that absorbs what enters within 0.01 mm: what leaves
            # is the boundary's reflection alone.
            args.sigma_a = [100.0] * 3
            args.sigma_s_prime = [0.0] * 3
        aov = mi.load_dict(scene_dict(mi, ply, args.scene, 0, args, 64, args.seed, aov=True))
        # The aov film: R, G, B, A of the (empty) nested result, then the position.
        pp = np.array(mi.render(aov, seed=args.seed))
        alpha = pp[..., 3]
        channels = []
        for c in range(3):
            v = render(mi, ply, args, c, args.seed * 3 + c)
            channels.append(v)
            print(f"channel {'RGB'[c]}: mean {v[alpha > 0.999].mean():.5f}", file=sys.stderr)
    rgba = np.stack(channels + [alpha], -1).astype(np.float32)
    # Where the mesh covers a pixel only partly, the mean position is of its hits.
    position = (pp[..., -3:] / np.maximum(alpha, 1e-6)[..., None]).astype(np.float32)
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    out_channels = {"Combined": rgba, "Position": position}
    tmp = f"{args.out}.tmp-{os.getpid()}.exr"
    with OpenEXR.File(header, out_channels) as f:
        f.write(tmp)
    os.replace(tmp, args.out)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
