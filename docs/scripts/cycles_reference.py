"""A path-traced reference of dermis's default scene in Blender's Cycles (>= 4.0).

Run with the Python of a venv that holds the `bpy` wheel (docs/records/2026-11-26-path-tracer-cycles.md,
"Against a path tracer"):

    python3 -m venv /work/bpy-venv && /work/bpy-venv/bin/pip install bpy==4.2.0 numpy OpenEXR
    /work/bpy-venv/bin/python docs/scripts/cycles_reference.py --out ref.exr \
        --env uniform --sss-method skin --width 192 --height 240 --samples 1024 --seed 1

The scan (assets/head/lee-perry-smith/, 50.3 mm per glTF unit) with its albedo,
normal and specular maps; skin is Cycles' Principled BSDF (Blender 4's energy-
conserving dielectric layer over the base) with random-walk subsurface
scattering at Jensen et al. 2001's skin1 diffuse mean free paths; the camera
and environment of assets/default.toml. Output: a multilayer linear EXR
(Standard view transform, no denoising), layers Combined (alpha = coverage) and
Position (world, Blender units, Z up), with --normal-pass also Normal, written
to a temporary file and renamed.
"""

import argparse
import json
import math
import os
import sys

import bpy
from mathutils import Matrix, Vector

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
HEAD = os.path.join(REPO, "assets", "head", "lee-perry-smith")
MM_PER_UNIT = 50.3  # assets/default.toml

# Jensen, Marschner, Levoy & Hanrahan 2001, Table 1 "Skin1": sigma_s' = (0.74,
# 0.88, 1.01)/mm, sigma_a = (0.032, 0.17, 0.48)/mm; the diffuse mean free path
# 1/sqrt(3 sigma_a sigma_t') in mm: RANDOM_WALK_SKIN's "radius".
SKIN1_MFP_MM = (3.67, 1.37, 0.68)
SKIN_IOR = 1.4  # d'Eon & Luebke, GPU Gems 3 §14.3 (F0 = 0.028)

# dermis's specular (src/skin/specular.rs, docs/records/2026-11-22-specular-on-the-gpu.md "Calibration"): rho_s =
# 0.18 (1 + (0.16/0.18) t), t = min(s / (2 s_mean), 1), s the specular map's red
# channel (linear) and s_mean = 0.244 its area-weighted mean over the scan; the KS
# lobe at rho_s is rho_s/0.35 of a dielectric of F0 0.028 (0.736 at rho_s =
# 0.2575, normal incidence). Cycles' Specular IOR Level scales F0 by 2 x level.
KS_RHO_S = 0.18
KS_MAP_GAIN = 0.16 / 0.18
SPEC_MAP_MEAN = 0.244
KS_RHO_S_DIELECTRIC = 0.35
# Beckmann m = 0.3 (d'Eon's default, every region of the scan); Walter et al.
# 2007 match GGX's alpha to Beckmann's m; Blender's roughness is sqrt(alpha).
BECKMANN_M = 0.3

# assets/default.toml, in mm, +Y up.
CAMERA_POSITION_MM = (229.0, 119.0, 629.0)
CAMERA_TARGET_MM = (0.0, 60.0, 0.0)
CAMERA_FOV_Y_DEG = 30.0


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument(
        "--out", required=True, help="output .exr (multilayer); .json with --slab-reflectance"
    )
    p.add_argument(
        "--env",
        default="uniform",
        help="'uniform' (radiance 1, dermis: uniform:1,1,1) or a lat-long .hdr/.exr",
    )
    p.add_argument(
        "--camera",
        metavar="X,Y,Z:TX,TY,TZ:FOV",
        help="eye and target (dermis world, mm, +Y up) and vertical field of view "
        "(degrees), as a scene's [camera]; default: assets/default.toml's",
    )
    p.add_argument(
        "--sun",
        metavar="DX,DY,DZ:E",
        help="a directional light, as a scene's [[lights]]: the direction it travels "
        "(dermis world) and its irradiance facing it (the sky's radiance units), "
        "point-like",
    )
    p.add_argument(
        "--sky",
        type=float,
        default=1.0,
        help="the uniform sky's radiance (dermis: uniform:L)",
    )
    p.add_argument("--width", type=int, default=192)
    p.add_argument("--height", type=int, default=240)
    p.add_argument("--samples", type=int, default=1024)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument(
        "--sss", choices=["on", "off"], default="on", help="off: Lambertian base"
    )
    p.add_argument(
        "--specular",
        choices=["map", "dielectric", "off"],
        default="map",
        help="map: dermis's spatial strength; dielectric: IOR 1.4 everywhere",
    )
    p.add_argument(
        "--base",
        choices=["map", "black", "black-to-camera"],
        default="map",
        help="black: base colour 0 and no subsurface, so the image is the specular "
        "layer alone; black-to-camera: base colour 0 for camera rays only, so the "
        "image is the specular layer alone, reflecting the skin as it is lit "
        "(docs/records/2026-11-26-path-tracer-cycles.md, \"The specular against the reference's\")",
    )
    p.add_argument(
        "--occlusion",
        choices=["on", "off"],
        default="on",
        help="off: the head hides none of the sky from itself and reflects nothing "
        "onto itself (invisible to shadow, diffuse and glossy rays; the camera still "
        "sees it), as dermis's --occlusion off",
    )
    p.add_argument(
        "--bounces",
        type=int,
        default=8,
        help="max diffuse and glossy bounces (the SSS exit counts as one)",
    )
    p.add_argument(
        "--slab",
        metavar="R,G,B",
        help="instead of the head: a flat slab 1 m wide, 100 mm thick, of this "
        "linear albedo (no maps; specular at the map's mean), seen from above",
    )
    p.add_argument(
        "--slab-thickness",
        type=float,
        default=100.0,
        help="with --slab: its thickness in mm (with --sun 0,1,0:E and --sky 0, the "
        "light it transmits; docs/design/skin.md, \"Transmission against the walk\")",
    )
    p.add_argument(
        "--slab-edge",
        action="store_true",
        help="with --slab: a half plane 3 mm above it, hidden from the camera, "
        "shadows x < 0, and the camera sees 24 mm across the edge (the light "
        "the walk carries into the shadow; docs/design/skin.md)",
    )
    p.add_argument(
        "--slab-mu",
        type=float,
        default=1.0,
        help="with --slab: view the slab at this exit cosine (1: straight down)",
    )
    p.add_argument(
        "--skybox",
        action="store_true",
        help="show the environment behind the head (alpha 1 there: only to check "
        "the map's orientation against dermis's --skybox on)",
    )
    p.add_argument(
        "--sss-method",
        choices=["skin", "walk"],
        default="skin",
        help="RANDOM_WALK_SKIN (the radius is the diffuse mean free path, entry "
        "through the IOR) or RANDOM_WALK (index-matched; the radius / 4 pi and the "
        "albedo's fit give the extinction)",
    )
    p.add_argument(
        "--slab-reflectance",
        action="store_true",
        help="the slab (no specular) at base colours 0.02 ... 1: its total "
        "reflectance under the uniform sky and its radiance per exit angle, to "
        "--out (.json)",
    )
    p.add_argument(
        "--view",
        choices=["final", "albedo", "rho-s"],
        default="final",
        help="albedo: the albedo map as emission (to check the UVs); rho-s: dermis's "
        "rho_s (the KS intensity the specular map gives, before the level) as emission",
    )
    p.add_argument(
        "--subdivide",
        type=int,
        default=0,
        help="Catmull-Clark levels on the scan (UVs interpolated linearly): the "
        "walk then runs in a smoothed volume rather than the scan's flat "
        "triangles, to measure the facets' share of a comparison",
    )
    p.add_argument(
        "--normal-pass",
        action="store_true",
        help="also write the Normal pass (world, Blender axes): the shading normal "
        "the closures use, the normal map's included (docs/scripts/cycles_exit.py "
        "takes the exit cosine from it)",
    )
    args = p.parse_args(argv)
    if not args.out.lower().endswith(".json" if args.slab_reflectance else ".exr"):
        p.error("--out must end in .json with --slab-reflectance, else .exr")
    out_dir = os.path.dirname(os.path.abspath(args.out))
    if not os.path.isdir(out_dir):
        p.error(f"--out: no folder {out_dir}")
    def floats(text, n, what):
        try:
            v = tuple(float(c) for c in text.split(","))
        except ValueError:
            v = ()
        if len(v) != n:
            p.error(f"{what}: {n} comma-separated numbers, not {text!r}")
        return v

    if args.camera:
        parts = args.camera.split(":")
        if len(parts) != 3:
            p.error("--camera: X,Y,Z:TX,TY,TZ:FOV")
        args.camera = (
            floats(parts[0], 3, "--camera eye"),
            floats(parts[1], 3, "--camera target"),
            floats(parts[2], 1, "--camera fov")[0],
        )
    if args.sun:
        parts = args.sun.split(":")
        if len(parts) != 2:
            p.error("--sun: DX,DY,DZ:E")
        args.sun = (floats(parts[0], 3, "--sun direction"), floats(parts[1], 1, "--sun E")[0])
    if args.env != "uniform" and not os.path.isfile(args.env):
        p.error(f"--env: no file {args.env}")
    if args.slab is not None:
        try:
            args.slab = tuple(float(c) for c in args.slab.split(","))
        except ValueError:
            p.error("--slab takes three numbers R,G,B")
        if len(args.slab) != 3 or not all(0.0 <= c <= 1.0 for c in args.slab):
            p.error("--slab takes three numbers in [0, 1]")
    if not args.slab_thickness > 0.0:
        p.error("--slab-thickness must be > 0")
    if not 0.0 < args.slab_mu <= 1.0:
        p.error("--slab-mu must be in (0, 1]")
    if not 0 <= args.subdivide <= 3:
        p.error("--subdivide takes 0 to 3 levels")
    for name in ("width", "height", "samples", "threads"):
        if getattr(args, name) < 1:
            p.error(f"--{name} must be >= 1")
    if args.bounces < 0 or args.seed < 0:
        p.error("--bounces and --seed must be >= 0")
    return args


def to_blender(v_mm):
    """dermis world (mm, +Y up) to Blender's (units, +Z up), as the glTF importer
    turns the mesh: (x, y, z) -> (x, -z, y)."""
    x, y, z = (c / MM_PER_UNIT for c in v_mm)
    return Vector((x, -z, y))


def import_head():
    bpy.ops.import_scene.gltf(filepath=os.path.join(HEAD, "LeePerrySmith.glb"))
    meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    if len(meshes) != 1:
        raise SystemExit(f"expected one mesh in the GLB, found {len(meshes)}")
    head = meshes[0]
    # The importer flips v (v' = 1 - v) for glTF's top-left origin; the scan's
    # maps are authored for a bottom-left origin (assets/default.toml), so the
    # glTF v is already Blender's. Flip back in the mesh, not the lookup, so the
    # tangents the normal map uses follow the v the maps were painted for.
    for loop_uv in head.data.uv_layers.active.data:
        loop_uv.uv[1] = 1.0 - loop_uv.uv[1]
    return head


def image(name, colorspace):
    img = bpy.data.images.load(os.path.join(HEAD, name))
    img.colorspace_settings.name = colorspace
    return img


def rho_s_map(nodes, links):
    """dermis's rho_s from the specular map (src/skin/specular.rs, map_rho_s):
    0.18 (1 + (0.16/0.18) t), t = min(s / (2 s_mean), 1); the socket giving it."""
    spec = nodes.new("ShaderNodeTexImage")
    spec.image = image("Map-SPEC.jpg", "Non-Color")
    red = nodes.new("ShaderNodeSeparateColor")
    links.new(spec.outputs["Color"], red.inputs["Color"])
    t = nodes.new("ShaderNodeMath")
    t.operation = "MULTIPLY"
    t.use_clamp = True
    t.inputs[1].default_value = 1.0 / (2.0 * SPEC_MAP_MEAN)
    links.new(red.outputs["Red"], t.inputs[0])
    rho = nodes.new("ShaderNodeMath")
    rho.operation = "MULTIPLY_ADD"
    rho.inputs[1].default_value = KS_RHO_S * KS_MAP_GAIN
    rho.inputs[2].default_value = KS_RHO_S
    links.new(t.outputs["Value"], rho.inputs[0])
    return rho.outputs["Value"]


def skin_material(args):
    mat = bpy.data.materials.new("skin")
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    if args.slab:
        albedo = nodes.new("ShaderNodeRGB")
        albedo.outputs["Color"].default_value = args.slab + (1.0,)
    else:
        albedo = nodes.new("ShaderNodeTexImage")
        albedo.image = image("Map-COL.jpg", "sRGB")
    if args.view in ("albedo", "rho-s"):
        emit = nodes.new("ShaderNodeEmission")
        if args.view == "albedo":
            links.new(albedo.outputs["Color"], emit.inputs["Color"])
        else:
            links.new(rho_s_map(nodes, links), emit.inputs["Color"])
        links.new(emit.outputs["Emission"], out.inputs["Surface"])
        return mat

    bsdf = nodes.new("ShaderNodeBsdfPrincipled")
    bsdf.distribution = "MULTI_GGX"
    # Cycles' kernel/closure/bssrdf.h, bssrdf_setup_radius: RANDOM_WALK_SKIN
    # scales the radius so that it is diffusion theory's 1/sigma_tr (Jensen's
    # diffuse mean free path) at the IOR, and refracts on entry; RANDOM_WALK
    # scales it by 1/(4 pi) and exits index-matched (docs/design/skin.md).
    bsdf.subsurface_method = "RANDOM_WALK_SKIN" if args.sss_method == "skin" else "RANDOM_WALK"
    if args.base == "black":
        # The specular layer alone: nothing under it reflects.
        bsdf.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    elif args.base == "black-to-camera":
        # Black where the camera looks, the albedo map for every other ray: the
        # layer alone, with what it reflects of the skin.
        path = nodes.new("ShaderNodeLightPath")
        mix = nodes.new("ShaderNodeMix")
        mix.data_type = "RGBA"
        # The Mix node has a socket of each type per name; take the colour ones.
        socket = {s.identifier: s for s in list(mix.inputs) + list(mix.outputs)}
        links.new(path.outputs["Is Camera Ray"], socket["Factor_Float"])
        links.new(albedo.outputs["Color"], socket["A_Color"])
        socket["B_Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        links.new(socket["Result_Color"], bsdf.inputs["Base Color"])
    else:
        links.new(albedo.outputs["Color"], bsdf.inputs["Base Color"])
    bsdf.inputs["Metallic"].default_value = 0.0
    bsdf.inputs["Roughness"].default_value = math.sqrt(BECKMANN_M)
    bsdf.inputs["IOR"].default_value = SKIN_IOR
    sss_on = args.sss == "on" and args.base != "black"
    bsdf.inputs["Subsurface Weight"].default_value = 1.0 if sss_on else 0.0
    bsdf.inputs["Subsurface Radius"].default_value = SKIN1_MFP_MM
    bsdf.inputs["Subsurface Scale"].default_value = 1.0 / MM_PER_UNIT
    bsdf.inputs["Subsurface Anisotropy"].default_value = 0.0
    if args.sss_method == "skin":
        bsdf.inputs["Subsurface IOR"].default_value = SKIN_IOR

    level = bsdf.inputs["Specular IOR Level"]
    if args.slab:
        # The map's mean everywhere: t = 1/2.
        rho_s = KS_RHO_S * (1.0 + 0.5 * KS_MAP_GAIN)
        level.default_value = 0.5 * rho_s / KS_RHO_S_DIELECTRIC if args.specular == "map" else 0.0
        if args.specular == "dielectric":
            level.default_value = 0.5
        links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
        return mat

    normal_tex = nodes.new("ShaderNodeTexImage")
    normal_tex.image = image("Infinite-Level_02_Tangent_SmoothUV.jpg", "Non-Color")
    normal_map = nodes.new("ShaderNodeNormalMap")
    normal_map.space = "TANGENT"
    links.new(normal_tex.outputs["Color"], normal_map.inputs["Color"])
    links.new(normal_map.outputs["Normal"], bsdf.inputs["Normal"])

    if args.specular == "off":
        level.default_value = 0.0
    elif args.specular == "dielectric":
        level.default_value = 0.5
    else:
        # level = 0.5 rho_s / rho_s(dielectric)
        lvl = nodes.new("ShaderNodeMath")
        lvl.operation = "MULTIPLY"
        lvl.inputs[1].default_value = 0.5 / KS_RHO_S_DIELECTRIC
        links.new(rho_s_map(nodes, links), lvl.inputs[0])
        links.new(lvl.outputs["Value"], level)
    links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return mat


def world(args):
    w = bpy.data.worlds.new("env")
    w.use_nodes = True
    nodes, links = w.node_tree.nodes, w.node_tree.links
    bg = nodes["Background"]
    bg.inputs["Strength"].default_value = 1.0
    if args.view != "final":
        bg.inputs["Color"].default_value = (0, 0, 0, 1)
    elif args.env == "uniform":
        bg.inputs["Color"].default_value = (args.sky, args.sky, args.sky, 1)
    else:
        tex = nodes.new("ShaderNodeTexEnvironment")
        tex.image = bpy.data.images.load(os.path.abspath(args.env))
        tex.image.colorspace_settings.name = "Linear Rec.709"
        tex.interpolation = "Closest"  # dermis's reference: piecewise constant
        # Cycles looks up u = 0.5 - atan2(y, x)/2pi (Blender axes), so u = 0.5
        # looks along +X; dermis's u = 0.5 looks along its -Z, Blender's +Y
        # (docs/design/lighting.md). Turning the direction by -90° about Z first gives
        # dermis's u.
        coord = nodes.new("ShaderNodeTexCoord")
        mapping = nodes.new("ShaderNodeMapping")
        mapping.vector_type = "VECTOR"
        mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(-90.0))
        links.new(coord.outputs["Generated"], mapping.inputs["Vector"])
        links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
        links.new(tex.outputs["Color"], bg.inputs["Color"])
    return w


def slab(thickness_mm):
    """A 1 m x 1 m box this thick, top face at z = 0 (Blender units)."""
    z = -0.5 * thickness_mm / MM_PER_UNIT
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, 0.0, z))
    box = bpy.context.active_object
    box.scale = (1000.0 / MM_PER_UNIT, 1000.0 / MM_PER_UNIT, thickness_mm / MM_PER_UNIT)
    return box


def slab_edge():
    """A 1 m half plane 3 mm above the slab over x < 0, casting a straight
    shadow; the camera does not see it."""
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(-500.0 / MM_PER_UNIT, 0.0, 3.0 / MM_PER_UNIT))
    plane = bpy.context.active_object
    plane.scale = (1000.0 / MM_PER_UNIT, 1000.0 / MM_PER_UNIT, 1.0)
    plane.visible_camera = False
    # Black: the light the slab sends up must not come back into the shadow.
    black = bpy.data.materials.new("occluder")
    black.use_nodes = True
    black.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0, 0, 0, 1)
    black.node_tree.nodes["Principled BSDF"].inputs["Specular IOR Level"].default_value = 0.0
    plane.data.materials.append(black)
    return plane


def slab_camera(args):
    """Orthographic, 20 mm (with --slab-edge 24 mm) across the slab's centre,
    straight down."""
    data = bpy.data.cameras.new("camera")
    data.type = "ORTHO"
    data.ortho_scale = (24.0 if args.slab_edge else 20.0) / MM_PER_UNIT
    cam = bpy.data.objects.new("camera", data)
    bpy.context.scene.collection.objects.link(cam)
    tilt_slab_camera(cam, args.slab_mu)
    return cam


def tilt_slab_camera(cam, mu):
    """Look at the slab's centre from 500 mm away at cos(angle from normal) mu."""
    a = math.acos(mu)
    d = 500.0 / MM_PER_UNIT
    cam.location = (0.0, -d * math.sin(a), d * math.cos(a))
    cam.rotation_euler = (a, 0.0, 0.0)


def camera(args):
    data = bpy.data.cameras.new("camera")
    data.sensor_fit = "VERTICAL"
    eye_mm, target_mm, fov = CAMERA_POSITION_MM, CAMERA_TARGET_MM, CAMERA_FOV_Y_DEG
    if args.camera:
        eye_mm, target_mm, fov = args.camera
    data.angle_y = math.radians(fov)
    data.clip_start = 0.01
    data.clip_end = 1000.0
    cam = bpy.data.objects.new("camera", data)
    eye = to_blender(eye_mm)
    target = to_blender(target_mm)
    # Look along -Z with +Y up, dermis's look_at with world up (+Y, Blender's +Z).
    rot = (target - eye).to_track_quat("-Z", "Y").to_matrix().to_4x4()
    cam.matrix_world = Matrix.Translation(eye) @ rot
    bpy.context.scene.collection.objects.link(cam)
    return cam


def main():
    argv = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else sys.argv[1:]
    args = parse_args(argv)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    if args.slab_reflectance:
        args.slab, args.specular, args.sss = (0.5, 0.5, 0.5), "off", "on"
    head = slab(args.slab_thickness) if args.slab else import_head()
    if args.subdivide and not args.slab:
        sub = head.modifiers.new("subdivide", "SUBSURF")
        sub.subdivision_type = "CATMULL_CLARK"
        sub.levels = sub.render_levels = args.subdivide
        sub.uv_smooth = "NONE"
    if args.slab and args.slab_edge:
        slab_edge()
    head.data.materials.clear()
    head.data.materials.append(skin_material(args))
    if args.occlusion == "off":
        head.visible_shadow = False
        head.visible_diffuse = False
        head.visible_glossy = False
        head.visible_transmission = False
    scene.world = world(args)
    scene.camera = slab_camera(args) if args.slab else camera(args)
    if args.sun:
        direction, irradiance = args.sun
        sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
        sun.data.energy, sun.data.angle = irradiance, 0.0
        # A sun shines along its local -Z; dermis's direction is unitless, so
        # only its turn (to_blender's axes) matters.
        travel = to_blender(direction).normalized()
        sun.rotation_euler = travel.to_track_quat("-Z", "Y").to_euler()
        scene.collection.objects.link(sun)

    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = args.samples
    cy.seed = args.seed
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.max_bounces = max(args.bounces, 1)
    cy.diffuse_bounces = args.bounces
    cy.glossy_bounces = args.bounces
    cy.transmission_bounces = args.bounces
    cy.transparent_max_bounces = 8
    cy.caustics_reflective = True
    cy.caustics_refractive = True
    cy.blur_glossy = 0.0
    # Box filter over the pixel: the pixel's mean, as dermis's mip-mapped maps.
    cy.pixel_filter_type = "BOX"
    cy.filter_width = 1.0
    scene.render.threads_mode = "FIXED"
    scene.render.threads = args.threads
    scene.render.resolution_x = args.width
    scene.render.resolution_y = args.height
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = not args.skybox
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.render.use_compositing = False
    scene.render.use_sequencer = False
    scene.view_layers[0].use_pass_position = True
    scene.view_layers[0].use_pass_normal = args.normal_pass
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"

    out = os.path.abspath(args.out)
    tmp = os.path.join(os.path.dirname(out), "." + os.path.basename(out) + ".tmp.exr")
    scene.render.filepath = tmp
    scene.render.use_file_extension = False
    try:
        if args.slab_reflectance:
            slab_reflectance(args, head.data.materials[0], tmp, out)
        else:
            bpy.ops.render.render(write_still=True)
            os.replace(tmp, out)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    print(f"wrote {out}", flush=True)


def slab_reflectance(args, material, tmp, out):
    """The slab's total (hemispherical) reflectance under the uniform sky of 1,
    2 int_0^1 L(mu) mu dmu over the exit cosine mu, for base colours 0.02 ... 1
    (three per render): the random walk's exit is not Lambertian, so its
    radiance is read at the 4 Gauss-Legendre nodes of mu on [0, 1]."""
    import numpy as np
    import OpenEXR

    colour = next(n for n in material.node_tree.nodes if n.type == "RGB")
    cam = bpy.context.scene.camera
    nodes, weights = np.polynomial.legendre.leggauss(4)
    mus, weights = (nodes + 1) / 2, weights / 2
    base = [0.02, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 1.0]
    radiance = np.zeros((len(mus), len(base)))
    for i in range(0, len(base), 3):
        colour.outputs["Color"].default_value = tuple(base[i : i + 3]) + (1.0,)
        for k, mu in enumerate(mus):
            tilt_slab_camera(cam, mu)
            bpy.ops.render.render(write_still=True)
            px = OpenEXR.File(tmp).parts[0].channels["ViewLayer.Combined"].pixels
            radiance[k, i : i + 3] = px[..., :3].reshape(-1, 3).astype(np.float64).mean(0)
    reflectance = 2 * (weights * mus) @ radiance
    table = {
        "what": "Cycles random walk (no specular) on a slab under a uniform sky of 1: "
        "hemispherical reflectance, and the radiance at each exit cosine mu",
        "blender": bpy.app.version_string,
        "samples": args.samples,
        "pixels": args.width * args.height,
        "base": base,
        "reflectance": [round(r, 5) for r in reflectance],
        "mu": [round(m, 5) for m in mus],
        "radiance": [[round(r, 5) for r in row] for row in radiance],
        "edge": shadow_edge(colour, cam, tmp),
    }
    part = out + ".tmp"
    with open(part, "w") as f:
        json.dump(table, f, indent=1)
    os.replace(part, out)


def shadow_edge(colour, cam, tmp):
    """How far the walk carries light: the slab at the scan's mean albedo under
    a sun straight above, a half-plane 3 mm over it shading x < 0, no sky; the
    distance from 25 % to 75 % of the lit level across the shadow's edge, per
    channel (a profile R(r) gives the edge integral of R over the half plane)."""
    import numpy as np
    import OpenEXR

    scene = bpy.context.scene
    albedo = (0.58, 0.33, 0.28)  # the scan's mean linear albedo (--view albedo)
    colour.outputs["Color"].default_value = albedo + (1.0,)
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy, sun.data.angle = 1.0, 0.0
    scene.collection.objects.link(sun)
    bpy.ops.mesh.primitive_plane_add(size=1.0)
    blocker = bpy.context.active_object
    blocker.scale = (400.0 / MM_PER_UNIT, 1000.0 / MM_PER_UNIT, 1.0)
    blocker.location = (-200.0 / MM_PER_UNIT, 0.0, 3.0 / MM_PER_UNIT)
    across_mm = 24.0
    tilt_slab_camera(cam, 1.0)
    cam.location = (0.0, 0.0, 2.0 / MM_PER_UNIT)  # under the blocker
    cam.data.clip_start = 1e-3
    cam.data.ortho_scale = across_mm / MM_PER_UNIT
    scene.render.resolution_x, scene.render.resolution_y = 192, 8
    bpy.ops.render.render(write_still=True)
    px = OpenEXR.File(tmp).parts[0].channels["ViewLayer.Combined"].pixels
    row = px[..., :3].astype(np.float64).mean(0)
    x = (np.arange(len(row)) + 0.5) / len(row) * across_mm - across_mm / 2
    lit = row[-24:].mean(0)

    def crossing(f, t):
        """Where f first rises through t, linear between pixels."""
        i = int(np.argmax(f > t))
        return x[i - 1] + (t - f[i - 1]) / (f[i] - f[i - 1]) * (x[i] - x[i - 1])

    widths = []
    for c in range(3):
        f = row[:, c] / lit[c]
        widths.append(float(crossing(f, 0.75) - crossing(f, 0.25)))
    return {
        "albedo": albedo,
        "mm_per_pixel": across_mm / len(row),
        "lit_radiance": [round(v, 5) for v in lit],
        "width_25_75_mm": [round(w, 3) for w in widths],
    }


if __name__ == "__main__":
    main()
    # bpy 4.2 can crash in its own teardown at exit (SIGSEGV after the file is
    # written); leave without it.
    os._exit(0)
