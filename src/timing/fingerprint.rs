//! Where a measurement was made: the device, its driver, the CPU behind it (on
//! lavapipe the "GPU" is the CPU), the thread count, the clock, validation. Two
//! runs' timings compare only when their fingerprints agree (pyperf refuses
//! runs of different machines; Bencher keys thresholds by testbed).

use crate::gpu::DeviceInfo;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub struct Fingerprint {
    pub device: String,
    /// Vulkan's device type: "CPU", "discrete GPU", …
    pub device_type: String,
    pub driver: String,
    pub api_version: String,
    /// `model name` of /proc/cpuinfo (or the platform's equivalent), "unknown".
    pub cpu_model: String,
    /// Cores this process may use (`std::thread::available_parallelism`).
    pub cpu_cores: usize,
    /// `LP_NUM_THREADS` (lavapipe's rasterizer threads), when set.
    pub lp_num_threads: Option<String>,
    /// "gpu-timestamp" or "host-fence"; empty before the first frame.
    pub clock: String,
    /// The Khronos validation layer was on (it costs CPU time per call).
    pub validation: bool,
    /// Work counters were recorded around every pass (`render --counters`);
    /// false in reports written before they existed.
    #[serde(default)]
    pub counters: bool,
}

impl Fingerprint {
    /// This process on `device`; `clock` is filled in by the caller that timed.
    pub fn of(device: &DeviceInfo) -> Self {
        Self {
            device: device.name.clone(),
            device_type: device.device_type.clone(),
            driver: format!("{} {}", device.driver_name, device.driver_info)
                .trim()
                .to_string(),
            api_version: device.api_version.clone(),
            cpu_model: cpu_model(),
            cpu_cores: std::thread::available_parallelism().map_or(0, |n| n.get()),
            lp_num_threads: std::env::var("LP_NUM_THREADS").ok(),
            clock: String::new(),
            validation: device.validation,
            counters: false,
        }
    }

    /// One line per field that differs: "cpu_cores: 2 → 16".
    pub fn differences(&self, other: &Fingerprint) -> Vec<String> {
        let opt = |v: &Option<String>| v.clone().unwrap_or_else(|| "unset".into());
        [
            ("device", self.device.clone(), other.device.clone()),
            (
                "device_type",
                self.device_type.clone(),
                other.device_type.clone(),
            ),
            ("driver", self.driver.clone(), other.driver.clone()),
            (
                "api_version",
                self.api_version.clone(),
                other.api_version.clone(),
            ),
            ("cpu_model", self.cpu_model.clone(), other.cpu_model.clone()),
            (
                "cpu_cores",
                self.cpu_cores.to_string(),
                other.cpu_cores.to_string(),
            ),
            (
                "LP_NUM_THREADS",
                opt(&self.lp_num_threads),
                opt(&other.lp_num_threads),
            ),
            ("clock", self.clock.clone(), other.clock.clone()),
            (
                "validation",
                self.validation.to_string(),
                other.validation.to_string(),
            ),
            (
                "counters",
                self.counters.to_string(),
                other.counters.to_string(),
            ),
        ]
        .into_iter()
        .filter(|(_, a, b)| a != b)
        .map(|(k, a, b)| format!("{k}: {a} → {b}"))
        .collect()
    }
}

/// The CPU's model name (Linux: /proc/cpuinfo), or "unknown".
pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find(|l| l.starts_with("model name") || l.starts_with("Model"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown".into())
}

/// A run's identity for rows of concatenated files: UTC time to the second,
/// then the process id and sub-second nanoseconds in hex (unique per process).
pub fn run_id() -> String {
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap_or_default();
    format!(
        "{}-{:x}{:08x}",
        humantime::format_rfc3339_seconds(std::time::UNIX_EPOCH + now)
            .to_string()
            .replace([':', '-'], ""),
        std::process::id(),
        now.subsec_nanos()
    )
}

/// Now, RFC 3339 in UTC to the second ("2026-11-25T23:40:01Z").
pub fn timestamp() -> String {
    humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn differences_name_each_field() {
        let a = Fingerprint {
            device: "llvmpipe".into(),
            cpu_cores: 2,
            ..Default::default()
        };
        let mut b = a.clone();
        assert!(a.differences(&b).is_empty());
        b.cpu_cores = 16;
        b.lp_num_threads = Some("4".into());
        assert_eq!(
            a.differences(&b),
            ["cpu_cores: 2 → 16", "LP_NUM_THREADS: unset → 4"]
        );
    }

    #[test]
    fn run_ids_are_distinct_and_timestamps_utc() {
        let (a, b) = (run_id(), run_id());
        assert_ne!(a, b);
        assert!(a.starts_with("20") && a.contains('T'), "{a}");
        let t = timestamp();
        assert!(t.ends_with('Z') && t.len() == 20, "{t}");
    }
}
