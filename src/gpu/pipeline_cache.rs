//! The driver's pipeline cache (VkPipelineCache) kept on disk, so that a
//! device compiles each pipeline once per machine rather than once per run.
//!
//! The file, `<folder>/pipelines-<vendor id>-<device id>.bin`, is a header of
//! dermis' own ([`MAGIC`], the data's length and FNV-1a 64) then the driver's
//! data, whose own header (the Vulkan spec's VkPipelineCacheHeaderVersionOne)
//! must name this device: vendor id, device id and pipelineCacheUUID. A file
//! that fails a check is not given to the driver: it is ignored (a warning
//! when damaged, a note when made by another driver or device) and replaced
//! when the context ends. Written whole or not at all (`atomic`).

use crate::cache::fnv1a64;
use crate::error::{Result, VkResultExt};
use ash::vk;
use std::path::{Path, PathBuf};

/// The first bytes of a dermis pipeline cache file (format version 1).
const MAGIC: &[u8; 8] = b"dermPC01";
/// Magic, data length (u64) and the data's FNV-1a 64 (u64), little-endian.
const FILE_HEADER: usize = 24;
/// The Vulkan header: headerSize, headerVersion, vendorID, deviceID (u32 each)
/// and pipelineCacheUUID (16 bytes).
const VK_HEADER: usize = 32;
/// A larger file is not read (a cache that grew without bound is dropped).
const MAX_BYTES: u64 = 256 << 20;

/// What the driver's data must say about the device it came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct DeviceKey {
    pub vendor_id: u32,
    pub device_id: u32,
    pub uuid: [u8; vk::UUID_SIZE],
}

impl DeviceKey {
    pub fn of(props: &vk::PhysicalDeviceProperties) -> Self {
        Self {
            vendor_id: props.vendor_id,
            device_id: props.device_id,
            uuid: props.pipeline_cache_uuid,
        }
    }

    /// The cache file's path in `folder`.
    pub fn file_in(&self, folder: &Path) -> PathBuf {
        folder.join(format!(
            "pipelines-{:04x}-{:04x}.bin",
            self.vendor_id, self.device_id
        ))
    }
}

/// Why a file's data is not given to the driver.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum Rejected {
    /// Truncated, the wrong format, or its checksum does not match: a warning.
    Damaged(String),
    /// Whole, but from another driver or device: expected after a driver update.
    OtherDevice(String),
}

/// `data` in a dermis pipeline cache file.
pub(crate) fn encode(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(FILE_HEADER + data.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&(data.len() as u64).to_le_bytes());
    out.extend_from_slice(&fnv1a64(data).to_le_bytes());
    out.extend_from_slice(data);
    out
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap())
}

/// The driver's data in `file`, if the file is whole and the data's Vulkan
/// header names `key`'s device.
pub(crate) fn decode<'a>(file: &'a [u8], key: &DeviceKey) -> Result<&'a [u8], Rejected> {
    let damaged = |why: &str| Err(Rejected::Damaged(why.into()));
    if file.len() < FILE_HEADER || &file[..8] != MAGIC {
        return damaged("not a dermis pipeline cache (no header)");
    }
    let data = &file[FILE_HEADER..];
    if u64_at(file, 8) != data.len() as u64 {
        return damaged("truncated or extended (its length does not match its header)");
    }
    if u64_at(file, 16) != fnv1a64(data) {
        return damaged("its checksum does not match its data");
    }
    // The spec's header, least significant byte first.
    if data.len() < VK_HEADER {
        return damaged("shorter than the Vulkan header");
    }
    let header_size = u32_at(data, 0) as usize;
    if header_size < VK_HEADER || header_size > data.len() || u32_at(data, 4) != 1 {
        return damaged("its Vulkan header is not VK_PIPELINE_CACHE_HEADER_VERSION_ONE");
    }
    let (vendor_id, device_id) = (u32_at(data, 8), u32_at(data, 12));
    if vendor_id != key.vendor_id || device_id != key.device_id || data[16..32] != key.uuid {
        return Err(Rejected::OtherDevice(format!(
            "made by device {vendor_id:04x}:{device_id:04x} or another driver version"
        )));
    }
    Ok(data)
}

/// A device's pipeline cache and the file it came from and goes back to.
pub(crate) struct PipelineCache {
    pub raw: vk::PipelineCache,
    /// `None`: not kept on disk.
    file: Option<PathBuf>,
    /// FNV-1a 64 of the data given to the driver, if any: unchanged data is
    /// not written again.
    loaded: Option<u64>,
}

impl PipelineCache {
    /// A cache seeded from the file of `key`'s device in `folder` (`None`: an
    /// empty cache that is not saved).
    pub fn new(device: &ash::Device, key: &DeviceKey, folder: Option<&Path>) -> Result<Self> {
        let file = folder.map(|f| key.file_in(f));
        let bytes = file.as_deref().and_then(read);
        let data = match (&file, &bytes) {
            (Some(path), Some(bytes)) => match decode(bytes, key) {
                Ok(data) => Some(data),
                Err(Rejected::Damaged(why)) => {
                    log::warn!(
                        "pipeline cache {} is ignored and will be replaced: {why}",
                        path.display()
                    );
                    None
                }
                Err(Rejected::OtherDevice(why)) => {
                    log::info!("pipeline cache {} is replaced: {why}", path.display());
                    None
                }
            },
            _ => None,
        };
        let mut info = vk::PipelineCacheCreateInfo::default();
        if let Some(data) = data {
            info = info.initial_data(data);
        }
        let raw =
            unsafe { device.create_pipeline_cache(&info, None) }.vk("vkCreatePipelineCache")?;
        Ok(Self {
            raw,
            file,
            loaded: data.map(fnv1a64),
        })
    }

    /// Writes the driver's data back to the file if it changed (a failure is a
    /// warning: the cache only saves time), then destroys the cache.
    /// `pipelines_made`: none made, nothing to keep.
    pub fn save_and_destroy(&self, device: &ash::Device, pipelines_made: bool) {
        if let (Some(path), true) = (&self.file, pipelines_made) {
            match unsafe { device.get_pipeline_cache_data(self.raw) } {
                Ok(data) if Some(fnv1a64(&data)) != self.loaded => {
                    let written = path
                        .parent()
                        .map_or(Ok(()), std::fs::create_dir_all)
                        .map_err(|e| e.to_string())
                        .and_then(|()| {
                            crate::atomic::write_atomic(path, encode(&data))
                                .map_err(|e| e.to_string())
                        });
                    if let Err(e) = written {
                        log::warn!("pipeline cache {} not saved: {e}", path.display());
                    }
                }
                Ok(_) => {}
                Err(e) => log::warn!("pipeline cache not saved: vkGetPipelineCacheData: {e}"),
            }
        }
        unsafe { device.destroy_pipeline_cache(self.raw, None) };
    }
}

/// The file's bytes; a missing file is an empty cache, an unreadable or
/// oversized one a warning.
fn read(path: &Path) -> Option<Vec<u8>> {
    let len = match std::fs::metadata(path) {
        Ok(m) => m.len(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return None,
        Err(e) => {
            log::warn!("pipeline cache {} is ignored: {e}", path.display());
            return None;
        }
    };
    if len > MAX_BYTES {
        log::warn!(
            "pipeline cache {} is ignored and will be replaced: {len} bytes",
            path.display()
        );
        return None;
    }
    std::fs::read(path)
        .map_err(|e| log::warn!("pipeline cache {} is ignored: {e}", path.display()))
        .ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key() -> DeviceKey {
        DeviceKey {
            vendor_id: 0x10de,
            device_id: 0x2335,
            uuid: *b"0123456789abcdef",
        }
    }

    /// Driver data as the spec lays it out: its header for `k`, then `body`.
    fn driver_data(k: &DeviceKey, body: &[u8]) -> Vec<u8> {
        let mut d = Vec::new();
        for v in [32u32, 1, k.vendor_id, k.device_id] {
            d.extend_from_slice(&v.to_le_bytes());
        }
        d.extend_from_slice(&k.uuid);
        d.extend_from_slice(body);
        d
    }

    #[test]
    fn a_whole_file_of_this_device_gives_back_its_data() {
        let data = driver_data(&key(), b"compiled pipelines");
        assert_eq!(decode(&encode(&data), &key()), Ok(&data[..]));
        assert_eq!(
            key().file_in(Path::new("/c")),
            Path::new("/c/pipelines-10de-2335.bin")
        );
    }

    #[test]
    fn a_damaged_file_is_rejected_as_damaged() {
        let file = encode(&driver_data(&key(), b"compiled pipelines"));
        let damaged = |f: &[u8]| matches!(decode(f, &key()), Err(Rejected::Damaged(_)));
        assert!(damaged(b""), "empty");
        assert!(damaged(&file[..FILE_HEADER - 1]), "a cut header");
        assert!(damaged(&file[..file.len() - 1]), "truncated");
        let mut longer = file.clone();
        longer.push(0);
        assert!(damaged(&longer), "extended");
        for at in [0, 9, 17, FILE_HEADER + 3, file.len() - 1] {
            let mut flipped = file.clone();
            flipped[at] ^= 0x40;
            assert!(damaged(&flipped), "a bit flipped at byte {at}");
        }
        let mut short = driver_data(&key(), b"");
        short.truncate(VK_HEADER - 1);
        assert!(damaged(&encode(&short)), "shorter than the Vulkan header");
        let mut version = driver_data(&key(), b"x");
        version[4] = 2;
        assert!(damaged(&encode(&version)), "another header version");
        let mut size = driver_data(&key(), b"x");
        size[0] = 200;
        assert!(damaged(&encode(&size)), "a header longer than the data");
    }

    #[test]
    fn a_file_of_another_device_or_driver_is_rejected_as_such() {
        let other = |k: DeviceKey| {
            matches!(
                decode(&encode(&driver_data(&k, b"x")), &key()),
                Err(Rejected::OtherDevice(_))
            )
        };
        assert!(other(DeviceKey {
            vendor_id: 0x1002,
            ..key()
        }));
        assert!(other(DeviceKey {
            device_id: 1,
            ..key()
        }));
        assert!(other(DeviceKey {
            uuid: *b"0123456789abcdeF",
            ..key()
        }));
    }
}
