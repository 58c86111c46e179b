//! Shared test harness: every GPU test runs with the Khronos validation layer and
//! synchronization validation, and fails on any warning or error it reports,
//! including leaks reported when the device is destroyed.
#![allow(dead_code)]

use dermis::gpu::{Context, ContextOptions, ValidationLog};
use std::path::Path;
use std::sync::{Arc, Mutex, MutexGuard};

/// Runs `f` on a validated context, destroys the context, then asserts the layer
/// said nothing of warning or error severity.
pub fn with_gpu<T>(f: impl FnOnce(&Arc<Context>) -> T) -> T {
    let (out, log) = with_gpu_log(f);
    assert_clean(&log);
    out
}

/// One test's context at a time. With two or more contexts alive in one
/// process, NVIDIA's driver (580.159, the Debian 1.3.239 validation layer)
/// kills a test thread with SIGSEGV, an instruction fetch from an unmapped
/// library, whenever another test's context is destroyed (`--test-threads 2`:
/// every run; `1`: none; README, "Tests"). A test's GPU work is the device's
/// anyway: lavapipe runs each context on every core.
static ONE_CONTEXT: Mutex<()> = Mutex::new(());

/// The device to the caller alone while the guard lives: what in-process GPU
/// tests hold, and what a test takes around a `dermis` run whose timings it
/// judges, so that no other test's GPU work shares the cores meanwhile.
pub fn device_turn() -> MutexGuard<'static, ()> {
    // A test that failed while holding it must not fail the others.
    ONE_CONTEXT.lock().unwrap_or_else(|p| p.into_inner())
}

/// Like [`with_gpu`] but hands the log back instead of asserting on it.
pub fn with_gpu_log<T>(f: impl FnOnce(&Arc<Context>) -> T) -> (T, Arc<ValidationLog>) {
    // Compiled afresh: no test depends on what an earlier run left
    // (tests/it/pipeline_cache.rs tests the cache itself).
    with_gpu_cache_log(None, f)
}

/// Like [`with_gpu_log`], with the on-disk pipeline cache in `pipeline_cache`.
pub fn with_gpu_cache_log<T>(
    pipeline_cache: Option<&Path>,
    f: impl FnOnce(&Arc<Context>) -> T,
) -> (T, Arc<ValidationLog>) {
    let _one = device_turn();
    let ctx = Context::new(&ContextOptions {
        validation: true,
        device: std::env::var("DERMIS_DEVICE").ok(),
        display: None,
        pipeline_cache: pipeline_cache.map(Path::to_path_buf),
    })
    .expect("a Vulkan device with VK_LAYER_KHRONOS_validation (see README)");
    let log = ctx.validation().expect("validation is on");
    let out = f(&ctx);
    assert_eq!(
        Arc::strong_count(&ctx),
        1,
        "a GPU object outlived the test; the device would not be destroyed"
    );
    drop(ctx);
    (out, log)
}

pub fn assert_clean(log: &ValidationLog) {
    let messages = log.messages();
    assert!(
        messages.is_empty(),
        "validation reported {} message(s):\n{}",
        messages.len(),
        messages.join("\n")
    );
}

/// Deterministic values in [0, 1) that f16 represents exactly (k / 256).
pub fn pattern(n: usize, seed: u32) -> Vec<f32> {
    let mut state = seed.wrapping_mul(2_654_435_761).wrapping_add(1);
    (0..n)
        .map(|_| {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            ((state >> 24) & 0xff) as f32 / 256.0
        })
        .collect()
}

pub fn to_f16_bytes(values: &[f32]) -> Vec<u8> {
    values
        .iter()
        .flat_map(|&v| half::f16::from_f32(v).to_le_bytes())
        .collect()
}

pub fn from_f16_bytes(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(2)
        .map(|c| half::f16::from_le_bytes([c[0], c[1]]).to_f32())
        .collect()
}

pub fn round_f16(v: f32) -> f32 {
    half::f16::from_f32(v).to_f32()
}

/// Splits a CSV line, honouring quoted fields (the device and environment
/// columns hold commas).
pub fn csv_fields(line: &str) -> Vec<String> {
    let (mut fields, mut cur, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            '"' => quoted = !quoted,
            ',' if !quoted => fields.push(std::mem::take(&mut cur)),
            c => cur.push(c),
        }
    }
    fields.push(cur);
    fields
}
