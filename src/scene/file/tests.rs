//! The scene file's tests: parsing, validation, docs/reference/scene-format.md's examples.

use super::*;
use crate::scene::env::SkyParams;

fn parse(text: &str) -> Result<SceneFile, SceneError> {
    parse_scene(text, Path::new("/scenes/scene.toml"))
}

fn err(text: &str) -> String {
    match parse(text) {
        Ok(s) => panic!("accepted: {text}\n{s:?}"),
        Err(e) => {
            let msg = e.to_string();
            assert!(msg.starts_with("/scenes/scene.toml: "), "{msg}");
            assert!(!msg.contains('\n'), "{msg}");
            msg
        }
    }
}

/// The repository root: this file lives at `src/scene/file/tests.rs`.
fn repo_root() -> PathBuf {
    let here = Path::new(file!());
    let file = if here.is_absolute() {
        here.to_path_buf()
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join(here)
    };
    file.ancestors().nth(4).map(Path::to_path_buf).unwrap()
}

/// The ```toml blocks of docs/reference/scene-format.md.
fn doc_examples() -> Vec<String> {
    let doc = repo_root().join("docs/reference/scene-format.md");
    let text = std::fs::read_to_string(&doc).unwrap();
    let mut blocks = Vec::new();
    let mut current: Option<String> = None;
    for line in text.lines() {
        match (&mut current, line.trim_start()) {
            (None, l) if l.starts_with("```toml") => current = Some(String::new()),
            (Some(_), l) if l.starts_with("```") => blocks.extend(current.take()),
            (Some(block), _) => {
                block.push_str(line);
                block.push('\n');
            }
            _ => {}
        }
    }
    blocks
}

#[test]
fn scenes_by_name() {
    let d = scene_by_name(None).unwrap();
    assert!(
        d.mesh.as_ref().unwrap().ends_with("LeePerrySmith.glb"),
        "{d:?}"
    );
    assert_eq!(d.mm_per_unit, Some(50.3));
    assert_eq!(d.textures.uv_origin, UvOrigin::BottomLeft);
    assert_eq!(
        scene_by_name(Some(Path::new(BUILTIN))).unwrap(),
        SceneFile::default()
    );
    assert!(scene_by_name(Some(Path::new("no/such.toml"))).is_err());
}

#[test]
fn empty_file_is_the_default_scene() {
    let scene = parse("").unwrap();
    assert_eq!(scene, SceneFile::default());
    assert!(SceneFile::default().validate().is_ok());
    assert_eq!(scene.mesh, None);
    assert_eq!(
        scene.environment.source,
        EnvSource::Sky(SkyParams::default())
    );
    assert_eq!(scene.skin.mix, 0.5);
    assert_eq!(scene.skin.profile, None);
    assert_eq!(scene.skin.regions, None);
    assert_eq!(scene.render.irradiance_resolution, 4096);
    assert_eq!(scene.render.gamma, Gamma::Srgb);
}

#[test]
fn full_file_parses_and_resolves_paths() {
    let text = r#"
mesh = "meshes/head.glb"
mm_per_unit = 50.3

[textures]
albedo = "maps/albedo.jpg"
normal = "/abs/normal.png"

[environment]
source = "env/studio.exr"
rotation_deg = 90
intensity = 2.5

[camera]
orbit = { yaw_deg = 30, pitch_deg = 10, distance_mm = 600 }
fov_deg = 25

[[lights]]
kind = "directional"
direction = [0, -1, -1]
color = [1, 0.9, 0.8]
intensity = 3
angular_diameter_deg = 0.53

[[lights]]
kind = "point"
position = [0, 500, 500]
shadow = false

[skin]
mix = 0.25
kernel = "accurate"
occlusion = "off"
blur_width = 0.5
blur_amount = 0.75
profile = [
  { variance_mm2 = 0.01, weights = [0.5, 0.5, 0.5] },
  { variance_mm2 = 1.0, weights = [0.5, 0.5, 0.5] },
]

[render]
width = 640
height = 480
irradiance_resolution = 1024
irradiance_shading = "compute"
exposure = -1.5
gamma = 2.2
tone_curve = "neutral"
skybox = false
background = [0.1, 0.2, 0.3]
glow = true
glow_intensity = 0.5
"#;
    let s = parse(text).unwrap();
    assert_eq!(s.mesh, Some(PathBuf::from("/scenes/meshes/head.glb")));
    assert_eq!(s.mm_per_unit, Some(50.3));
    assert_eq!(
        s.textures.albedo,
        Some(PathBuf::from("/scenes/maps/albedo.jpg"))
    );
    assert_eq!(s.textures.normal, Some(PathBuf::from("/abs/normal.png")));
    assert_eq!(s.textures.specular, None);
    assert_eq!(
        s.environment.source,
        EnvSource::File(PathBuf::from("/scenes/env/studio.exr"))
    );
    assert_eq!(s.environment.intensity, 2.5);
    assert_eq!(s.camera.fov_deg, 25.0);
    assert_eq!(s.lights.len(), 2);
    assert_eq!(s.lights[0].kind, LightKind::Directional);
    assert!(s.lights[0].shadow);
    assert_eq!(s.lights[0].angular_diameter_deg, 0.53);
    assert_eq!(s.lights[1].angular_diameter_deg, 0.0);
    assert_eq!(s.lights[1].color, [1.0, 1.0, 1.0]);
    assert!(!s.lights[1].shadow);
    assert_eq!(s.skin.kernel, Kernel::Accurate);
    assert_eq!(s.skin.occlusion, Occlusion::Off);
    assert_eq!(s.skin.profile.as_ref().map(Vec::len), Some(2));
    assert_eq!(s.render.gamma, Gamma::Power(2.2));
    assert_eq!(s.render.exposure, Some(-1.5));
    assert_eq!(s.render.tone_curve, ToneCurve::Neutral);
    assert_eq!(s.render.irradiance_shading, IrradianceShading::Compute);
    assert!(!s.render.skybox && s.render.glow);
    assert_eq!(s.render.background, [0.1, 0.2, 0.3]);
    assert_eq!(s.render.glow_intensity, 0.5);
    assert_eq!((s.skin.blur_width, s.skin.blur_amount), (0.5, 0.75));
    assert!(!s.textures.test_texture);

    // Orbit: yaw 30, pitch 10, 600 mm from the centre.
    let centre = Vec3::new(1.0, 2.0, 3.0);
    let (eye, target, up) = s.camera.eye_target_up(centre);
    assert_eq!(target, centre);
    assert_eq!(up, Vec3::Y);
    assert!(((eye - centre).length() - 600.0).abs() < 1e-3);
    let d = (eye - centre) / 600.0;
    assert!((d.y - 10f32.to_radians().sin()).abs() < 1e-6);
    assert!((d.x / d.z - 30f32.to_radians().tan()).abs() < 1e-5);
}

#[test]
fn environment_keywords_are_not_paths() {
    for src in [
        "sky",
        "sky:elevation=30,azimuth=10,turbidity=3",
        "uniform:1,1,1",
    ] {
        let s = parse(&format!("[environment]\nsource = \"{src}\"")).unwrap();
        assert_eq!(s.environment.source, src.parse::<EnvSource>().unwrap());
    }
    let s = parse("[environment]\nsource = \"skylight.hdr\"").unwrap();
    assert_eq!(
        s.environment.source,
        EnvSource::File(PathBuf::from("/scenes/skylight.hdr"))
    );
    let s = parse_scene("mesh = \"a.glb\"", Path::new("scene.toml")).unwrap();
    assert_eq!(s.mesh, Some(PathBuf::from("./a.glb")));
    let s =
        parse("[environment]\nsource = \"cube:f/px.hdr, nx.hdr,py.hdr,ny.hdr,pz.hdr,/abs/nz.hdr\"")
            .unwrap();
    let EnvSource::Cube(faces) = &s.environment.source else {
        panic!("{:?}", s.environment.source)
    };
    assert_eq!(faces[0], PathBuf::from("/scenes/f/px.hdr"));
    assert_eq!(faces[1], PathBuf::from("/scenes/nx.hdr"));
    assert_eq!(faces[5], PathBuf::from("/abs/nz.hdr"));
}

#[test]
fn bad_environment_sources_name_the_file_and_line() {
    for (src, needle) in [
        (
            "uniform:1,nan,1",
            "environment source 'uniform:1,nan,1': radiance NaN must be finite and >= 0",
        ),
        ("uniform", "expected uniform:R,G,B or uniform:V"),
        ("sky:foo=1", "unknown key 'foo'"),
        ("sky:elevation=95", "sky: elevation 95° is outside [0, 90]"),
        ("cube:a.hdr,b.hdr", "six face files"),
        (" ", "environment.source is empty"),
    ] {
        let msg = err(&format!("[environment]\nsource = \"{src}\""));
        assert!(
            msg.contains("line 2,") && msg.contains(needle),
            "{src}: {msg}"
        );
    }
}

#[test]
fn environment_lights_auto_or_a_count() {
    assert_eq!(parse("").unwrap().environment.lights, LightsMode::Auto);
    for (text, mode) in [
        ("\"auto\"", LightsMode::Auto),
        ("0", LightsMode::Count(0)),
        ("3", LightsMode::Count(3)),
        ("8", LightsMode::Count(8)),
        ("\"2\"", LightsMode::Count(2)),
    ] {
        let s = parse(&format!("[environment]\nlights = {text}")).unwrap();
        assert_eq!(s.environment.lights, mode, "{text}");
    }
    for (text, needle) in [
        ("-1", "got '-1'"),
        ("9", "got '9'"),
        ("\"sometimes\"", "got 'sometimes'"),
        ("\"-2\"", "got '-2'"),
        ("1.5", "floating point `1.5`"),
        ("true", "boolean `true`"),
    ] {
        let msg = err(&format!("[environment]\nlights = {text}"));
        assert!(
            msg.contains("line 2,") && msg.contains("environment.lights") && msg.contains(needle),
            "{text}: {msg}"
        );
    }
    // The same grammar on the command line and in JSON.
    for mode in [LightsMode::Auto, LightsMode::Count(0), LightsMode::Count(5)] {
        assert_eq!(mode.to_string().parse::<LightsMode>(), Ok(mode));
        let json = serde_json::to_string(&mode).unwrap();
        assert_eq!(serde_json::from_str::<LightsMode>(&json).unwrap(), mode);
    }
    assert_eq!(
        serde_json::to_string(&LightsMode::Auto).unwrap(),
        "\"auto\""
    );
    assert_eq!(serde_json::to_string(&LightsMode::Count(3)).unwrap(), "3");
    let e = "-3".parse::<LightsMode>().unwrap_err();
    assert_eq!(
        e,
        "expected \"auto\" or a number of lights in 0..=8, got '-3'"
    );
    assert!("".parse::<LightsMode>().unwrap_err().contains("got ''"));
}

#[test]
fn uv_origin_defaults_to_top_left() {
    assert_eq!(parse("").unwrap().textures.uv_origin, UvOrigin::TopLeft);
    for (text, origin) in [
        ("top-left", UvOrigin::TopLeft),
        ("bottom-left", UvOrigin::BottomLeft),
    ] {
        let s = parse(&format!("[textures]\nuv_origin = \"{text}\"")).unwrap();
        assert_eq!(s.textures.uv_origin, origin);
        assert_eq!(text.parse::<UvOrigin>(), Ok(origin));
    }
    assert!("TopLeft"
        .parse::<UvOrigin>()
        .unwrap_err()
        .contains("top-left or bottom-left"));
}

#[test]
fn camera_look_at() {
    let s = parse("[camera]\nposition = [0, 0, 500]\n").unwrap();
    let (eye, target, up) = s.camera.eye_target_up(Vec3::new(0.0, 10.0, 0.0));
    assert_eq!(eye, Vec3::new(0.0, 0.0, 500.0));
    assert_eq!(target, Vec3::new(0.0, 10.0, 0.0));
    assert_eq!(up, Vec3::Y);
    // Default camera: orbit yaw 0 pitch 0 puts the eye on +Z at 700 mm.
    let (eye, _, _) = Camera::default().eye_target_up(Vec3::ZERO);
    assert!((eye - Vec3::new(0.0, 0.0, 700.0)).length() < 1e-3);
}

#[test]
fn unknown_key_names_key_and_line() {
    let msg = err("[render]\nwidth = 10\n\n[camera]\nfov = 30\n");
    assert!(msg.contains("line 5, column 1"), "{msg}");
    assert!(msg.contains("unknown field `fov`"), "{msg}");
    let msg = err("meshes = \"a.glb\"");
    assert!(msg.contains("line 1") && msg.contains("`meshes`"), "{msg}");
    let msg = err("[skin]\nprofile = [{ variance_mm2 = 1, weights = [1,1,1], extra = 2 }]");
    assert!(msg.contains("line 2") && msg.contains("`extra`"), "{msg}");
    let msg = err("[[lights]]\nkind = \"point\"\nposition = [0,0,0]\ncolour = [1,1,1]");
    assert!(msg.contains("line 4") && msg.contains("`colour`"), "{msg}");
}

#[test]
fn syntax_and_type_errors_have_positions() {
    for (text, line, needle) in [
        ("[render\nwidth = 3", 1, ""),
        ("[render]\nwidth = ", 2, ""),
        ("mesh = \"unterminated", 1, ""),
        ("[render]\nwidth = \"wide\"", 2, "invalid type"),
        ("[render]\nwidth = -5", 2, ""),
        ("[render]\nwidth = 1.5", 2, "invalid type"),
        ("[skin]\nmix = \"half\"", 2, "invalid type"),
        ("[skin]\nkernel = \"box\"", 2, "unknown variant"),
        (
            "[textures]\nuv_origin = \"bottom-right\"",
            2,
            "unknown variant `bottom-right`, expected `top-left` or `bottom-left`",
        ),
        ("[[lights]]\nkind = \"spot\"", 2, "unknown variant"),
        ("[[lights]]\ndirection = [0,0,1]", 1, "missing field `kind`"),
        ("[render]\ngamma = \"s-rgb\"", 2, "srgb"),
        (
            "[render]\ntone_curve = \"sepia\"",
            2,
            "unknown variant `sepia`",
        ),
        (
            "[render]\nirradiance_shading = \"gpu\"",
            2,
            "unknown variant `gpu`, expected one of `auto`, `raster`, `compute`",
        ),
        ("[render]\nglow = \"yes\"", 2, "invalid type"),
        ("[camera]\nposition = [1, 2]", 2, ""),
        ("lights = 3", 1, "invalid type"),
    ] {
        let msg = err(text);
        assert!(msg.contains(&format!("line {line},")), "{text:?}: {msg}");
        assert!(msg.contains(needle), "{text:?}: {msg}");
    }
}

#[test]
fn out_of_range_values_are_rejected_with_their_key() {
    for (text, needle) in [
        (
            "[render]\nirradiance_resolution = 3000",
            "render.irradiance_resolution = 3000",
        ),
        (
            "[render]\nirradiance_resolution = 128",
            "render.irradiance_resolution = 128",
        ),
        (
            "[render]\nirradiance_resolution = 16384",
            "render.irradiance_resolution",
        ),
        (
            "[render]\nshadow_resolution = 1000",
            "render.shadow_resolution = 1000",
        ),
        ("[render]\nwidth = 0", "render.width = 0"),
        ("[render]\nheight = 16385", "render.height = 16385"),
        ("[render]\nexposure = nan", "render.exposure"),
        ("[render]\ngamma = 0", "render.gamma"),
        ("[skin]\nmix = 1.5", "skin.mix = 1.5"),
        ("[skin]\nmix = -0.1", "skin.mix"),
        ("[skin]\nmix = nan", "skin.mix = NaN"),
        ("[skin]\nblur_width = -1", "skin.blur_width = -1"),
        ("[skin]\nblur_width = 11", "skin.blur_width = 11"),
        ("[skin]\nblur_amount = 1.5", "skin.blur_amount = 1.5"),
        ("[skin]\ntransmission = -1", "skin.transmission = -1"),
        ("[skin]\ntransmission = nan", "skin.transmission = NaN"),
        ("[skin]\ntransmission = inf", "skin.transmission = inf"),
        (
            "[render]\nglow_intensity = -1",
            "render.glow_intensity = -1",
        ),
        (
            "[render]\nbackground = [0, 2, 0]",
            "render.background.g = 2",
        ),
        (
            "[skin]\nprofile = [{ variance_mm2 = 1, weights = [0.5, 1, 1] }]",
            "red weights sum to 0.5",
        ),
        (
            "[skin]\nprofile = [{ variance_mm2 = -1, weights = [1, 1, 1] }]",
            "skin.profile[0].variance_mm2 = -1",
        ),
        (
            "[skin]\nprofile = [{ variance_mm2 = 2, weights = [0.5, 0.5, 0.5] }, \
             { variance_mm2 = 1, weights = [0.5, 0.5, 0.5] }]",
            "increase strictly",
        ),
        ("[skin]\nprofile = []", "skin.profile is empty"),
        (
            "[skin]\nregions = [{ name = \"a\", rho_s = 0.2, m = 0.3 }]",
            "exactly 10",
        ),
        (
            "[[lights]]\nkind = \"directional\"\ndirection = [0, -1, 0]\nangular_diameter_deg = 50",
            "lights[0].angular_diameter_deg = 50",
        ),
        (
            "[[lights]]\nkind = \"point\"\nposition = [0, 0, 500]\nangular_diameter_deg = 1",
            "only directional lights",
        ),
        ("[camera]\nfov_deg = 1", "camera.fov_deg = 1"),
        ("[camera]\nfov_deg = 179", "camera.fov_deg = 179"),
        ("[camera]\nfov_deg = inf", "camera.fov_deg"),
        ("[camera]\nnear_mm = 100\nfar_mm = 50", "camera.far_mm"),
        ("[camera]\nposition = [0, nan, 0]", "camera.position"),
        (
            "[camera]\nposition = [0, 0, 1]\ntarget = [0, 0, 1]",
            "camera.target",
        ),
        (
            "[camera]\nposition = [0, 0, 1]\nup = [0, 0, 1]\ntarget = [0, 0, 0]",
            "parallel",
        ),
        (
            "[camera]\norbit = { pitch_deg = 90 }",
            "camera.orbit.pitch_deg",
        ),
        (
            "[camera]\norbit = { distance_mm = 0 }",
            "camera.orbit.distance_mm",
        ),
        ("[camera]\norbit = {}\nposition = [1, 1, 1]", "not both"),
        ("[camera]\ntarget = [1, 1, 1]", "need camera.position"),
        (
            "[[lights]]\nkind = \"directional\"",
            "lights[0].direction is required",
        ),
        (
            "[[lights]]\nkind = \"directional\"\ndirection = [0, 0, 0]",
            "lights[0].direction",
        ),
        (
            "[[lights]]\nkind = \"point\"\ndirection = [0, 0, 1]",
            "lights[0].direction",
        ),
        (
            "[[lights]]\nkind = \"point\"\nposition = [0, 0, 1]\nintensity = -1",
            "lights[0].intensity",
        ),
        (
            "[[lights]]\nkind = \"point\"\nposition = [0, 0, 1]\ncolor = [1, nan, 1]",
            "lights[0].color.g",
        ),
        ("mm_per_unit = 0", "mm_per_unit = 0"),
        ("mm_per_unit = -inf", "mm_per_unit"),
        ("[environment]\nintensity = -1", "environment.intensity"),
        (
            "[environment]\nrotation_deg = nan",
            "environment.rotation_deg",
        ),
        ("[environment]\nsource = \"\"", "environment.source"),
    ] {
        let msg = err(text);
        assert!(msg.contains(needle), "{text:?}: {msg}");
    }
    // Ten custom regions are fine; one bad m is not.
    let mut regions = String::from("[skin]\nregions = [\n");
    for i in 0..10 {
        let m = if i == 7 { 0.0 } else { 0.35 };
        regions.push_str(&format!("{{ name = \"r{i}\", rho_s = 0.15, m = {m} }},\n"));
    }
    regions.push(']');
    assert!(err(&regions).contains("skin.regions[7].m"));
    let fixed = parse(&regions.replace("m = 0 }", "m = 0.2 }")).unwrap();
    assert_eq!(fixed.skin.regions.as_ref().unwrap()[7].m, 0.2);
    assert_eq!(fixed.skin.regions.as_ref().unwrap()[9].name, "r9");
}

#[test]
fn missing_file_is_an_io_error() {
    let path = std::env::temp_dir().join("dermis-no-such-dir/none.toml");
    let msg = load_scene(&path).unwrap_err().to_string();
    assert!(
        msg.contains("none.toml") && msg.contains("cannot read"),
        "{msg}"
    );
}

#[test]
fn truncated_files_fail_cleanly() {
    let text = doc_examples().into_iter().last().unwrap();
    let mut rejected = 0;
    for cut in 1..text.len() {
        let Some(prefix) = text.get(..cut) else {
            continue;
        };
        if let Err(e) = parse(prefix) {
            assert!(!e.to_string().contains('\n'));
            rejected += 1;
        }
    }
    // Many prefixes end mid-token; they must all be reported, not panic.
    assert!(rejected > text.len() / 4, "{rejected} of {}", text.len());
}

#[test]
fn doc_examples_parse_and_validate() {
    let examples = doc_examples();
    assert!(
        examples.len() >= 2,
        "docs/reference/scene-format.md has no ```toml examples"
    );
    for (i, text) in examples.iter().enumerate() {
        if let Err(e) = parse(text) {
            panic!("docs example {i} fails: {e}");
        }
    }
}

#[test]
fn lee_perry_smith_example_loads_end_to_end() {
    // The example is a scene file in the repository root, beside assets/.
    let text = doc_examples().into_iter().last().unwrap();
    let scene = parse_scene(&text, &repo_root().join("head.toml")).unwrap();
    assert_eq!(scene.mm_per_unit, Some(50.3));
    let mesh_path = scene.mesh.as_deref().unwrap();
    let mesh = super::super::gltf::load_mesh(mesh_path, scene.mm_per_unit).unwrap();
    assert_eq!(mesh.triangle_count(), 17_684);
    use super::super::texture::{load_texture, Encoding};
    for (p, enc) in [
        (&scene.textures.albedo, Encoding::Srgb),
        (&scene.textures.normal, Encoding::Linear),
        (&scene.textures.specular, Encoding::Linear),
    ] {
        let t = load_texture(p.as_deref().unwrap(), enc).unwrap();
        assert_eq!((t.width, t.height), (1024, 1024));
    }
}

#[test]
fn fuzzed_scene_text_never_panics() {
    let text = doc_examples().into_iter().last().unwrap();
    let bytes = text.as_bytes();
    let mut rng = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        // xorshift64* (Vigna 2016)
        rng ^= rng >> 12;
        rng ^= rng << 25;
        rng ^= rng >> 27;
        rng.wrapping_mul(0x2545_F491_4F6C_DD1D)
    };
    let (mut ok, mut rejected) = (0, 0);
    for i in 0..400 {
        let mut b = bytes.to_vec();
        if i % 2 == 0 {
            b.truncate((next() as usize) % bytes.len());
        } else {
            for _ in 0..1 + next() % 4 {
                let at = (next() as usize) % b.len();
                b[at] ^= 1 << (next() % 8);
            }
        }
        let outcome = std::panic::catch_unwind(|| match String::from_utf8(b) {
            Ok(s) => parse(&s).map(|_| ()).map_err(|e| e.to_string()),
            Err(_) => Err("not UTF-8".to_string()),
        });
        match outcome {
            Ok(Ok(())) => ok += 1,
            Ok(Err(msg)) => {
                assert!(!msg.contains('\n'), "{msg}");
                rejected += 1
            }
            Err(_) => panic!("scene parser panicked on case {i}"),
        }
    }
    println!("fuzzed scenes: {ok} accepted, {rejected} rejected");
    assert!(rejected > 0 && ok > 0);
}

#[test]
fn a_medium_is_one_of_preset_coefficients_or_albedo_and_radius() {
    let s = parse("[skin.medium]\npreset = \"jensen-skin1\"\n").unwrap();
    assert_eq!(s.skin.medium.preset, Some(MediumPreset::JensenSkin1));
    assert!(!s.skin.medium.is_deon2007());
    assert!(SceneFile::default().skin.medium.is_deon2007());
    let s =
        parse("[skin.medium]\nsigma_a = [0.032, 0.17, 0.48]\nsigma_s_prime = [0.74, 0.88, 1.01]\n")
            .unwrap();
    assert_eq!(s.skin.medium.sigma_a, Some([0.032, 0.17, 0.48]));
    parse("[skin.medium]\nalbedo = [0.8, 0.5, 0.3]\ndmfp = [3.6, 1.4, 0.7]\n").unwrap();
    for (text, says) in [
        (
            "preset = \"jensen-skin1\"\nsigma_a = [1, 1, 1]\nsigma_s_prime = [1, 1, 1]",
            "not several",
        ),
        ("sigma_a = [0.1, 0.1, 0.1]", "go together"),
        (
            "sigma_a = [0.1, -0.1, 0.1]\nsigma_s_prime = [1, 1, 1]",
            "green value -0.1",
        ),
        (
            "sigma_a = [0.1, 0.1, 0.1]\nsigma_s_prime = [1, 0, 1]",
            "sigma_s_prime",
        ),
        (
            "albedo = [0.8, 0.5, 0.3]",
            "exactly one of `mfp` and `dmfp`",
        ),
        ("albedo = [0.8, 1.5, 0.3]\nmfp = [1, 1, 1]", "in (0, 1)"),
        (
            "albedo = [0.8, 0.5, 0.3]\nmfp = [1, 1, 1]\ndmfp = [1, 1, 1]",
            "exactly one",
        ),
        ("dmfp = [1, 1, 1]", "needs `albedo`"),
        ("preset = \"jensen-skin1\"\ninversion = \"dipole\"", "only"),
        ("preset = \"jensen-skin1\"\ng = 1.0", "skin.medium.g"),
        ("preset = \"jensen-skin1\"\nior = 0.5", "skin.medium.ior"),
        ("specular = \"boundary\"", "needs a medium"),
        ("preset = \"jensen-skin9\"", "jensen-skin9"),
    ] {
        let msg = err(&format!("[skin.medium]\n{text}\n"));
        assert!(msg.contains(says), "{text}: {msg}");
    }
    let msg = err(
        "[skin]\nprofile = [{ variance_mm2 = 1, weights = [1, 1, 1] }]\n\
                   [skin.medium]\npreset = \"jensen-skin1\"\n",
    );
    assert!(msg.contains("keep one"), "{msg}");
}
