//! Compiles every shader under `shaders-glsl/` to SPIR-V with glslang (the `glslang`
//! crate builds the reference compiler from source, no system tool), and writes
//! `$OUT_DIR/shaders.rs`: a table of (name, SPIR-V words) embedded in the binary.
//! Also sets `DERMIS_GIT_COMMIT` (for run reports) to the short commit hash.

use glslang::include::{IncludeHandler, IncludeResult, IncludeType};
use glslang::{
    Compiler, CompilerOptions, ShaderInput, ShaderSource, ShaderStage, SourceLanguage,
    SpirvVersion, Target, VulkanVersion,
};
use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Resolves `#include "x.glsl"` against `shaders-glsl/common/` (and the includer's
/// directory), recording every file it reads so cargo reruns when one changes.
struct Includes {
    root: PathBuf,
    seen: BTreeSet<PathBuf>,
}

impl IncludeHandler for Includes {
    fn include(
        &mut self,
        _ty: IncludeType,
        header: &str,
        includer: &str,
        _depth: usize,
    ) -> Option<IncludeResult> {
        let includer_dir = Path::new(includer).parent().map(Path::to_path_buf);
        let candidates = includer_dir
            .into_iter()
            .chain([self.root.join("common"), self.root.clone()])
            .map(|dir| dir.join(header));
        for path in candidates {
            if let Ok(data) = std::fs::read_to_string(&path) {
                self.seen.insert(path.clone());
                return Some(IncludeResult {
                    name: path.to_string_lossy().into_owned(),
                    data,
                });
            }
        }
        None
    }
}

fn stage_of(path: &Path) -> Option<ShaderStage> {
    match path.extension()?.to_str()? {
        "vert" => Some(ShaderStage::Vertex),
        "frag" => Some(ShaderStage::Fragment),
        "comp" => Some(ShaderStage::Compute),
        _ => None,
    }
}

/// `git rev-parse --short HEAD`, or "unknown" without git; `DERMIS_GIT_COMMIT` in
/// the environment wins (builds from a tarball). Reruns only when HEAD or the
/// branch it names moves (worktrees keep HEAD apart from the refs).
fn git_commit(manifest: &Path) {
    println!("cargo:rerun-if-env-changed=DERMIS_GIT_COMMIT");
    println!("cargo:rerun-if-env-changed=DERMIS_GIT_DIRTY");
    if let Ok(given) = std::env::var("DERMIS_GIT_COMMIT") {
        let dirty = std::env::var("DERMIS_GIT_DIRTY").unwrap_or_else(|_| "false".into());
        println!("cargo:rustc-env=DERMIS_GIT_COMMIT={given}");
        println!("cargo:rustc-env=DERMIS_GIT_DIRTY={}", dirty == "true");
        return;
    }
    let git = |args: &[&str]| -> Option<String> {
        let out = std::process::Command::new("git")
            .args(args)
            .current_dir(manifest)
            .output()
            .ok()?;
        let text = String::from_utf8(out.stdout).ok()?;
        (out.status.success() && !text.trim().is_empty()).then(|| text.trim().to_string())
    };
    let commit = git(&["rev-parse", "--short", "HEAD"]);
    let abs = |p: String| {
        let p = PathBuf::from(p);
        if p.is_absolute() {
            p
        } else {
            manifest.join(p)
        }
    };
    // A path cargo cannot find makes it rerun every build: name existing ones only.
    let watch = |path: &Path| {
        if path.exists() {
            println!("cargo:rerun-if-changed={}", path.display());
        }
    };
    if let Some(dir) = git(&["rev-parse", "--git-dir"]) {
        watch(&abs(dir).join("HEAD"));
    }
    if let (Some(common), Some(branch)) = (
        git(&["rev-parse", "--git-common-dir"]),
        git(&["symbolic-ref", "-q", "HEAD"]),
    ) {
        let common = abs(common);
        let loose = common.join(branch);
        // A packed branch gets its loose file on the next commit: watch the folder.
        if loose.exists() {
            watch(&loose);
        } else {
            watch(loose.parent().unwrap_or(&common));
        }
        watch(&common.join("packed-refs"));
    }
    // Dirty: the sources the binary is built from differ from the commit (edits,
    // or new files not yet committed). Cargo rescans these folders for changes.
    let built_from = [
        "src",
        "shaders-glsl",
        "build.rs",
        "Cargo.toml",
        "Cargo.lock",
    ];
    let mut status = vec!["status", "--porcelain", "--"];
    status.extend(built_from);
    let dirty = commit.is_some() && git(&status).is_some();
    for path in built_from {
        watch(&manifest.join(path));
    }
    let commit = commit.unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=DERMIS_GIT_COMMIT={commit}");
    println!("cargo:rustc-env=DERMIS_GIT_DIRTY={dirty}");
}

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
    git_commit(&manifest);
    let root = manifest.join("shaders-glsl");
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap());
    println!("cargo:rerun-if-changed={}", root.display());
    println!("cargo:rerun-if-changed={}", root.join("common").display());

    let mut sources: Vec<PathBuf> = std::fs::read_dir(&root)
        .expect("shaders-glsl/ is missing")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| stage_of(p).is_some())
        .collect();
    sources.sort();

    let compiler = Compiler::acquire().expect("glslang failed to initialise");
    let options = CompilerOptions {
        source_language: SourceLanguage::GLSL,
        target: Target::Vulkan {
            version: VulkanVersion::Vulkan1_2,
            spirv_version: SpirvVersion::SPIRV1_5,
        },
        ..Default::default()
    };

    let mut table = String::from("pub static SHADERS: &[(&str, &[u32])] = &[\n");
    let mut failures = Vec::new();
    // A source with an `#ifdef SKIP_WORK` block is compiled twice: as it is,
    // and with SKIP_WORK defined as `<name>:skip-work` (gpu::shaders), the
    // timing variant with its work skipped. Defining it in a second module
    // leaves the first one's SPIR-V, and so every image, as they were.
    let mut modules: Vec<(&PathBuf, String, String)> = Vec::new();
    for path in &sources {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(path).expect("unreadable shader source");
        if text.contains("#ifdef SKIP_WORK") {
            let (version, rest) = text.split_once('\n').expect("a #version line");
            let skipping = format!("{version}\n#define SKIP_WORK 1\n#line 2\n{rest}");
            modules.push((path, format!("{name}:skip-work"), skipping));
        }
        modules.push((path, name, text));
    }
    for (path, name, text) in modules {
        println!("cargo:rerun-if-changed={}", path.display());
        let source = ShaderSource::from(text);
        let mut includes = Includes {
            root: root.clone(),
            seen: BTreeSet::new(),
        };
        let stage = stage_of(path).unwrap();
        let spirv = ShaderInput::new(&source, stage, &options, None, Some(&mut includes))
            .map_err(|e| e.to_string())
            .and_then(|input| compiler.create_shader(input).map_err(|e| e.to_string()))
            .and_then(|shader| shader.compile().map_err(|e| e.to_string()));
        for inc in &includes.seen {
            println!("cargo:rerun-if-changed={}", inc.display());
        }
        match spirv {
            Ok(words) => {
                let file = out.join(format!("{}.spv", name.replace(':', ".")));
                let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
                std::fs::write(&file, bytes).expect("cannot write SPIR-V");
                // Stored as u32 words: 4-byte aligned, as ash::util::read_spv wants.
                writeln!(table, "    ({name:?}, &{words:?}),").unwrap();
            }
            // glslang names the top-level source "0"; put the real path in its place.
            Err(e) => failures.push(
                e.lines()
                    .filter(|l| l.starts_with("ERROR:") && !l.contains("compilation errors"))
                    .map(|l| l.replacen("ERROR: 0:", &format!("{}:", path.display()), 1))
                    .collect::<Vec<_>>()
                    .join("\n"),
            ),
        }
    }
    table.push_str("];\n");
    if !failures.is_empty() {
        for line in failures.iter().flat_map(|f| f.lines()) {
            println!("cargo:warning={line}");
        }
        panic!("GLSL compilation failed:\n\n{}", failures.join("\n\n"));
    }
    std::fs::write(out.join("shaders.rs"), table).expect("cannot write shaders.rs");
}
