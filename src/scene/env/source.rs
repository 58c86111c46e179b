//! The environment-source grammar, parsed once into an [`EnvSource`], and
//! [`resolve`], which turns a source into an [`EnvMap`].
//!
//! `uniform:R,G,B` / `uniform:V`, `sky`, `sky:elevation=30,azimuth=120,
//! turbidity=3,intensity=1` (keys optional, defaults from [`SkyParams`]),
//! `cube:PX,NX,PY,NY,PZ,NZ` (six face files), or a file path (anything else).

use std::fmt;
use std::path::PathBuf;
use std::str::FromStr;

use glam::Vec3;

use super::decode::{load, load_cube_faces};
use super::error::EnvError;
use super::map::{size_ok, EnvMap, SanitizeReport};
use super::sky::{render_sky, SkyParams};

/// Where an environment comes from (grammar in the module doc). Serialised as
/// its source string.
#[derive(Clone, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(try_from = "String", into = "String")]
pub enum EnvSource {
    /// Anything else: a `.hdr` / `.exr` file (equirect or cross).
    File(PathBuf),
    /// `cube:PX,NX,PY,NY,PZ,NZ`: six face files (+X, −X, +Y, −Y, +Z, −Z).
    Cube([PathBuf; 6]),
    /// `uniform:R,G,B` (or `uniform:V` for grey): constant radiance.
    Uniform(Vec3),
    /// `sky` or `sky:elevation=30,azimuth=120,turbidity=3,intensity=1`.
    Sky(SkyParams),
}

impl FromStr for EnvSource {
    type Err = EnvError;

    fn from_str(s: &str) -> Result<EnvSource, EnvError> {
        let bad = |detail: String| EnvError::BadSource {
            source_str: s.to_string(),
            detail,
        };
        let t = s.trim();
        if t.is_empty() {
            return Err(bad("empty source".into()));
        }
        if let Some(rest) = t.strip_prefix("uniform:") {
            let vals: Vec<&str> = rest.split(',').map(str::trim).collect();
            let mut v = Vec::with_capacity(3);
            for p in &vals {
                let x: f32 = p
                    .parse()
                    .map_err(|_| bad(format!("'{p}' is not a number")))?;
                if !x.is_finite() || x < 0.0 {
                    return Err(bad(format!("radiance {x} must be finite and >= 0")));
                }
                v.push(x);
            }
            return match v.as_slice() {
                [g] => Ok(EnvSource::Uniform(Vec3::splat(*g))),
                [r, g, b] => Ok(EnvSource::Uniform(Vec3::new(*r, *g, *b))),
                _ => Err(bad("expected uniform:R,G,B or uniform:V".into())),
            };
        }
        if t == "uniform" {
            return Err(bad("expected uniform:R,G,B or uniform:V".into()));
        }
        if t == "sky" {
            return Ok(EnvSource::Sky(SkyParams::default()));
        }
        if let Some(rest) = t.strip_prefix("cube:") {
            let faces: Vec<PathBuf> = rest.split(',').map(|p| PathBuf::from(p.trim())).collect();
            return <[PathBuf; 6]>::try_from(faces)
                .map(EnvSource::Cube)
                .map_err(|v| {
                    bad(format!(
                        "expected six face files (+X,-X,+Y,-Y,+Z,-Z), got {}",
                        v.len()
                    ))
                });
        }
        if let Some(rest) = t.strip_prefix("sky:") {
            let mut p = SkyParams::default();
            for kv in rest.split(',').map(str::trim).filter(|kv| !kv.is_empty()) {
                let (k, v) = kv
                    .split_once('=')
                    .ok_or_else(|| bad(format!("'{kv}' is not key=value")))?;
                let x: f32 = v
                    .trim()
                    .parse()
                    .map_err(|_| bad(format!("'{}' is not a number", v.trim())))?;
                match k.trim() {
                    "elevation" => p.elevation_deg = x,
                    "azimuth" => p.azimuth_deg = x,
                    "turbidity" => p.turbidity = x,
                    "intensity" => p.intensity = x,
                    other => {
                        return Err(bad(format!(
                            "unknown key '{other}' (elevation, azimuth, turbidity, intensity)"
                        )))
                    }
                }
            }
            p.validate()?;
            return Ok(EnvSource::Sky(p));
        }
        Ok(EnvSource::File(PathBuf::from(t)))
    }
}

impl TryFrom<String> for EnvSource {
    type Error = EnvError;

    fn try_from(s: String) -> Result<EnvSource, EnvError> {
        s.parse()
    }
}

impl From<EnvSource> for String {
    fn from(s: EnvSource) -> String {
        s.to_string()
    }
}

impl fmt::Display for EnvSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EnvSource::Uniform(c) => write!(f, "uniform:{},{},{}", c.x, c.y, c.z),
            EnvSource::Sky(p) => write!(
                f,
                "sky:elevation={},azimuth={},turbidity={},intensity={}",
                p.elevation_deg, p.azimuth_deg, p.turbidity, p.intensity
            ),
            EnvSource::Cube(faces) => {
                let names: Vec<String> = faces.iter().map(|p| p.display().to_string()).collect();
                write!(f, "cube:{}", names.join(","))
            }
            EnvSource::File(p) => write!(f, "{}", p.display()),
        }
    }
}

/// Produce the environment for a source. `width × height` is the size of
/// procedural maps (uniform, sky); files load at their own resolution.
pub fn resolve(
    src: &EnvSource,
    width: u32,
    height: u32,
) -> Result<(EnvMap, SanitizeReport), EnvError> {
    match src {
        EnvSource::File(p) => load(p),
        EnvSource::Cube(faces) => load_cube_faces(faces.each_ref().map(PathBuf::as_path)),
        _ if !size_ok(width, height) => Err(EnvError::BadSize { width, height }),
        EnvSource::Uniform(c) => {
            let mut env = EnvMap::uniform(*c, width, height);
            let r = env.sanitize();
            Ok((env, r))
        }
        EnvSource::Sky(p) => {
            p.validate()?;
            Ok((render_sky(p, width, height), SanitizeReport::default()))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_source(s: &str) -> Result<EnvSource, EnvError> {
        s.parse()
    }

    #[test]
    fn parse_sources() {
        assert_eq!(
            parse_source("uniform:1,0.5,0.25").unwrap(),
            EnvSource::Uniform(Vec3::new(1.0, 0.5, 0.25))
        );
        assert_eq!(
            parse_source("uniform:2").unwrap(),
            EnvSource::Uniform(Vec3::splat(2.0))
        );
        assert_eq!(
            parse_source("sky").unwrap(),
            EnvSource::Sky(SkyParams::default())
        );
        let EnvSource::Sky(p) = parse_source("sky:elevation=30,azimuth=120,turbidity=3").unwrap()
        else {
            panic!()
        };
        assert_eq!(
            (p.elevation_deg, p.azimuth_deg, p.turbidity),
            (30.0, 120.0, 3.0)
        );
        assert_eq!(
            parse_source("maps/a.hdr").unwrap(),
            EnvSource::File(PathBuf::from("maps/a.hdr"))
        );
        for bad in [
            "uniform:1,2",
            "uniform:a,b,c",
            "uniform:-1,0,0",
            "sky:foo=1",
            "sky:elevation=95",
            "sky:turbidity=1",
            "sky:elevation",
            "",
        ] {
            let e = parse_source(bad);
            assert!(e.is_err(), "{bad} should fail");
        }
        let (env, _) = resolve(&parse_source("uniform:1,2,3").unwrap(), 16, 8).unwrap();
        assert_eq!(env.texel(3, 3), Vec3::new(1.0, 2.0, 3.0));
        assert!(resolve(&EnvSource::Uniform(Vec3::ONE), 0, 8).is_err());
        let (sky, _) = resolve(&EnvSource::Sky(SkyParams::default()), 64, 32).unwrap();
        assert_eq!((sky.width, sky.height), (64, 32));
        let e = resolve(&EnvSource::File(PathBuf::from("/nonexistent/x.exr")), 1, 1).unwrap_err();
        assert!(e.to_string().contains("x.exr"));
    }

    #[test]
    fn cube_face_sources_parse() {
        let src = parse_source("cube:px.hdr, nx.hdr,py.hdr,ny.hdr,pz.hdr,nz.hdr").unwrap();
        let EnvSource::Cube(faces) = &src else {
            panic!("{src:?}")
        };
        assert_eq!(faces[1], PathBuf::from("nx.hdr"));
        assert_eq!(parse_source(&src.to_string()).unwrap(), src);
        let e = parse_source("cube:a.hdr,b.hdr").unwrap_err().to_string();
        assert!(e.contains("six face files"), "{e}");
        // Missing faces are a load error naming the file.
        let e = resolve(&src, 8, 4).unwrap_err().to_string();
        assert!(e.contains("px.hdr"), "{e}");
    }

    #[test]
    fn display_round_trips_and_serde_uses_the_string() {
        for s in [
            "uniform:1,0.5,0.25",
            "sky:elevation=12.5,azimuth=-40,turbidity=2.25,intensity=3",
            "cube:a/px.hdr,a/nx.hdr,a/py.hdr,a/ny.hdr,a/pz.hdr,a/nz.hdr",
            "/maps/studio.exr",
        ] {
            let src = parse_source(s).unwrap();
            assert_eq!(src.to_string(), s);
            assert_eq!(parse_source(&src.to_string()).unwrap(), src);
            let json = serde_json::to_string(&src).unwrap();
            assert_eq!(serde_json::from_str::<EnvSource>(&json).unwrap(), src);
        }
        // Messages name the source string.
        let e = parse_source("uniform:1,nan,1").unwrap_err().to_string();
        assert_eq!(
            e,
            "environment source 'uniform:1,nan,1': radiance NaN must be finite and >= 0"
        );
        let e = serde_json::from_str::<EnvSource>("\"sky:foo=1\"").unwrap_err();
        assert!(e.to_string().contains("unknown key 'foo'"), "{e}");
    }
}
