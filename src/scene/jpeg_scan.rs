//! Walks the Huffman-coded scans of a sequential JPEG and refuses the damage
//! libjpeg reports as "Corrupt JPEG data" (jdhuff.c, jdmarker.c; messages in
//! jerror.h): a bad Huffman code (JWRN_HUFF_BAD_CODE), a scan that runs out
//! of data before its last block (JWRN_HIT_MARKER, "premature end of data
//! segment"), bytes left between the last block and the next marker
//! (JWRN_EXTRANEOUS_DATA) and a missing or misnumbered restart marker
//! (JWRN_MUST_RESYNC). zune-jpeg's strict mode finds none of the last three:
//! it fills a short scan with zeros and ignores leftover bytes, so most random
//! byte changes in the scan decode silently to wrong pixels.
//! A changed byte desynchronises the codes after it, so the scan almost
//! always ends off its last byte; that is what libjpeg (and this walk) sees.
//!
//! Only the entropy decoding is done (no dequantisation, no IDCT): T.81 §F.2.2
//! (Huffman decoding of DC and AC coefficients), §B.2 (frame and scan
//! headers, interleaving), §F.2.2.3 (the DECODE procedure with MINCODE,
//! MAXCODE, VALPTR), §B.1.1.5 (stuffed bytes, fill bytes). Progressive and
//! arithmetic-coded frames are left to the decoder.

/// A Huffman table as T.81 §F.2.2.3 decodes it (Figure F.16).
#[derive(Clone)]
struct Table {
    /// Largest code of each length 1..=16, or −1 when there is none.
    maxcode: [i32; 17],
    /// The smallest code of each length.
    mincode: [i32; 17],
    /// Index in `values` of the first value of each length.
    valptr: [usize; 17],
    values: Vec<u8>,
}

impl Table {
    /// From a DHT segment's 16 counts and its values (T.81 §C, Figure C.1–C.2).
    fn new(counts: &[u8], values: &[u8]) -> Table {
        let mut t = Table {
            maxcode: [-1; 17],
            mincode: [0; 17],
            valptr: [0; 17],
            values: values.to_vec(),
        };
        let (mut code, mut k) = (0i32, 0usize);
        for len in 1..=16 {
            let n = usize::from(counts[len - 1]);
            if n > 0 {
                t.valptr[len] = k;
                t.mincode[len] = code;
                code += n as i32;
                k += n;
                t.maxcode[len] = code - 1;
            }
            code <<= 1;
        }
        t
    }
}

/// A frame component: its id and sampling factors.
struct Component {
    id: u8,
    h: u32,
    v: u32,
}

/// Reads the entropy-coded bits of one scan (T.81 §F.2.2.5, with libjpeg's
/// handling of stuffing: FF 00 is a data byte FF; FF FF… fill before a marker).
struct Bits<'a> {
    bytes: &'a [u8],
    /// The next byte to read.
    pos: usize,
    /// The current byte and how many of its bits are left.
    byte: u8,
    left: u8,
}

impl Bits<'_> {
    fn bit(&mut self) -> Result<u32, String> {
        if self.left == 0 {
            let b = *self
                .bytes
                .get(self.pos)
                .ok_or("truncated JPEG: the file ends inside a scan")?;
            if b == 0xFF {
                let mut next = self.pos + 1;
                while self.bytes.get(next) == Some(&0xFF) {
                    next += 1;
                }
                match self.bytes.get(next) {
                    Some(0x00) => self.pos = next + 1,
                    Some(&code) => {
                        return Err(format!(
                            "corrupt JPEG: premature end of data segment (marker FF {code:02X} at \
                             byte {} before the scan's last block)",
                            self.pos
                        ))
                    }
                    None => return Err("truncated JPEG: the file ends inside a scan".into()),
                }
            } else {
                self.pos += 1;
            }
            self.byte = b;
            self.left = 8;
        }
        self.left -= 1;
        Ok(u32::from(self.byte >> self.left) & 1)
    }

    fn bits(&mut self, n: u8) -> Result<u32, String> {
        let mut v = 0;
        for _ in 0..n {
            v = (v << 1) | self.bit()?;
        }
        Ok(v)
    }

    /// T.81 Figure F.16 (DECODE).
    fn decode(&mut self, t: &Table, what: &str) -> Result<u8, String> {
        let mut code = self.bit()? as i32;
        for len in 1..=16 {
            if code <= t.maxcode[len] {
                let i = t.valptr[len] + (code - t.mincode[len]) as usize;
                return t.values.get(i).copied().ok_or_else(|| {
                    format!("corrupt JPEG: {what} Huffman table has fewer values than codes")
                });
            }
            if len < 16 {
                code = (code << 1) | self.bit()? as i32;
            }
        }
        Err(format!(
            "corrupt JPEG: bad Huffman code in the scan near byte {}",
            self.pos
        ))
    }

    /// Skips to the next marker, the partial byte dropped; returns its code and
    /// position and how many bytes were skipped (libjpeg's next_marker counts
    /// them as "extraneous bytes before marker").
    fn next_marker(&mut self) -> Result<(u8, usize, usize), String> {
        self.left = 0;
        let mut skipped = 0;
        loop {
            let b = *self
                .bytes
                .get(self.pos)
                .ok_or("truncated JPEG: the file ends after a scan, before its end marker")?;
            if b != 0xFF {
                skipped += 1;
                self.pos += 1;
                continue;
            }
            let mut next = self.pos + 1;
            while self.bytes.get(next) == Some(&0xFF) {
                next += 1;
            }
            match self.bytes.get(next) {
                Some(0x00) => {
                    skipped += 2;
                    self.pos = next + 1;
                }
                Some(&code) => {
                    let at = self.pos;
                    self.pos = next + 1;
                    return Ok((code, at, skipped));
                }
                None => {
                    return Err(
                        "truncated JPEG: the file ends after a scan, before its end marker".into(),
                    )
                }
            }
        }
    }
}

/// Checks every Huffman-coded scan of a baseline or extended sequential JPEG
/// (SOF0, SOF1) as libjpeg would; other frames pass unchecked. `bytes` starts
/// with SOI; the marker structure is assumed already checked (texture.rs's
/// `check_jpeg_complete`), but nothing here indexes out of bounds if it is not.
pub fn check_scans(bytes: &[u8]) -> Result<(), String> {
    let mut dc: [Option<Table>; 4] = Default::default();
    let mut ac: [Option<Table>; 4] = Default::default();
    let mut components: Vec<Component> = Vec::new();
    let (mut width, mut height) = (0u32, 0u32);
    let mut restart_interval = 0u32;
    let mut pos = 2usize;
    let segment = |pos: usize| -> Result<(u8, &[u8]), String> {
        let head = bytes
            .get(pos..pos + 4)
            .ok_or("truncated JPEG: the file ends inside a marker")?;
        let len = usize::from(u16::from_be_bytes([head[2], head[3]]));
        let body = bytes
            .get(pos + 4..pos + 2 + len.max(2))
            .ok_or("truncated JPEG: the file ends inside a segment")?;
        Ok((head[1], body))
    };
    loop {
        // Fill bytes (FF FF…) may precede a marker (T.81 §B.1.1.2).
        while bytes.get(pos) == Some(&0xFF) && bytes.get(pos + 1) == Some(&0xFF) {
            pos += 1;
        }
        if bytes.get(pos) != Some(&0xFF) {
            return Err(format!("corrupt JPEG: expected a marker at byte {pos}"));
        }
        let code = *bytes.get(pos + 1).ok_or("truncated JPEG: no end marker")?;
        match code {
            0xD9 => return Ok(()),
            0x01 | 0xD0..=0xD8 => {
                pos += 2;
                continue;
            }
            _ => {}
        }
        let (_, body) = segment(pos)?;
        let next = pos + 2 + body.len() + 2;
        match code {
            // SOF0, SOF1: sequential, Huffman (T.81 §B.2.2).
            0xC0 | 0xC1 => {
                if body.len() < 6 {
                    return Err("corrupt JPEG: short frame header".into());
                }
                height = u32::from(u16::from_be_bytes([body[1], body[2]]));
                width = u32::from(u16::from_be_bytes([body[3], body[4]]));
                let n = usize::from(body[5]);
                let list = body
                    .get(6..6 + 3 * n)
                    .ok_or("corrupt JPEG: short frame header")?;
                components = list
                    .chunks_exact(3)
                    .map(|c| Component {
                        id: c[0],
                        h: u32::from(c[1] >> 4),
                        v: u32::from(c[1] & 15),
                    })
                    .collect();
                if components
                    .iter()
                    .any(|c| !(1..=4).contains(&c.h) || !(1..=4).contains(&c.v))
                {
                    return Err("corrupt JPEG: a sampling factor outside 1..=4".into());
                }
                if height == 0 {
                    // Height in a DNL marker after the first scan: rare; leave it.
                    return Ok(());
                }
            }
            // Other frame types (progressive, lossless, arithmetic): not walked.
            0xC2 | 0xC3 | 0xC5..=0xC7 | 0xC9..=0xCB | 0xCD..=0xCF => return Ok(()),
            // DHT (T.81 §B.2.4.2): one or more tables.
            0xC4 => {
                let mut t = body;
                while !t.is_empty() {
                    let head = t.get(..17).ok_or("corrupt JPEG: short Huffman table")?;
                    let (class, id) = (head[0] >> 4, usize::from(head[0] & 15));
                    let n: usize = head[1..17].iter().map(|&c| usize::from(c)).sum();
                    let values = t
                        .get(17..17 + n)
                        .ok_or("corrupt JPEG: short Huffman table")?;
                    if id > 3 || class > 1 {
                        return Err(format!("corrupt JPEG: Huffman table {class}/{id}"));
                    }
                    let table = Some(Table::new(&head[1..17], values));
                    if class == 0 {
                        dc[id] = table;
                    } else {
                        ac[id] = table;
                    }
                    t = &t[17 + n..];
                }
            }
            // DRI (T.81 §B.2.4.4).
            0xDD => {
                let r = body
                    .get(..2)
                    .ok_or("corrupt JPEG: short restart interval")?;
                restart_interval = u32::from(u16::from_be_bytes([r[0], r[1]]));
            }
            // SOS (T.81 §B.2.3), then its entropy-coded data.
            0xDA => {
                if components.is_empty() {
                    return Err("corrupt JPEG: a scan before the frame header".into());
                }
                let n = usize::from(*body.first().ok_or("corrupt JPEG: short scan header")?);
                let list = body
                    .get(1..1 + 2 * n)
                    .ok_or("corrupt JPEG: short scan header")?;
                let mut scan = Vec::new();
                for s in list.chunks_exact(2) {
                    let c = components
                        .iter()
                        .find(|c| c.id == s[0])
                        .ok_or_else(|| format!("corrupt JPEG: scan names component {}", s[0]))?;
                    let (d, a) = (usize::from(s[1] >> 4), usize::from(s[1] & 15));
                    let table = |set: &[Option<Table>; 4], i: usize, kind: &str| {
                        set.get(i).and_then(|t| t.clone()).ok_or_else(|| {
                            format!(
                                "corrupt JPEG: the scan uses {kind} Huffman table {i}, not defined"
                            )
                        })
                    };
                    scan.push((c, table(&dc, d, "DC")?, table(&ac, a, "AC")?));
                }
                if scan.is_empty() {
                    return Err("corrupt JPEG: a scan of no components".into());
                }
                pos = walk_scan(
                    bytes,
                    next,
                    &scan,
                    &components,
                    width,
                    height,
                    restart_interval,
                )?;
                continue;
            }
            _ => {}
        }
        pos = next;
    }
}

/// Decodes one scan's blocks from `start`; returns the position of the marker
/// after it.
fn walk_scan(
    bytes: &[u8],
    start: usize,
    scan: &[(&Component, Table, Table)],
    components: &[Component],
    width: u32,
    height: u32,
    restart_interval: u32,
) -> Result<usize, String> {
    let hmax = components.iter().map(|c| c.h).max().unwrap_or(1);
    let vmax = components.iter().map(|c| c.v).max().unwrap_or(1);
    // Blocks per MCU and MCU count (T.81 §A.2): a single-component scan is not
    // interleaved, one block per MCU over the component's own size.
    let (mcus, blocks_per): (u64, Vec<u32>) = if scan.len() == 1 {
        let c = scan[0].0;
        let cw = (width * c.h).div_ceil(hmax).div_ceil(8);
        let ch = (height * c.v).div_ceil(vmax).div_ceil(8);
        (u64::from(cw) * u64::from(ch), vec![1])
    } else {
        let mw = width.div_ceil(8 * hmax);
        let mh = height.div_ceil(8 * vmax);
        (
            u64::from(mw) * u64::from(mh),
            scan.iter().map(|(c, _, _)| c.h * c.v).collect(),
        )
    };
    let mut bits = Bits {
        bytes,
        pos: start,
        byte: 0,
        left: 0,
    };
    let mut restarts = 0u32;
    for mcu in 0..mcus {
        if restart_interval > 0 && mcu > 0 && mcu % u64::from(restart_interval) == 0 {
            let (code, at, skipped) = bits.next_marker()?;
            let expected = 0xD0 + (restarts % 8) as u8;
            if skipped > 0 {
                return Err(extraneous(skipped, code, at));
            }
            if code != expected {
                return Err(format!(
                    "corrupt JPEG: found marker FF {code:02X} at byte {at} instead of RST{}",
                    restarts % 8
                ));
            }
            restarts += 1;
        }
        for ((_, dc, ac), &blocks) in scan.iter().zip(&blocks_per) {
            for _ in 0..blocks {
                // DC: a size, then that many bits (T.81 §F.2.2.1).
                let s = bits.decode(dc, "a DC")?;
                if s > 15 {
                    return Err(format!("corrupt JPEG: a DC difference of {s} bits"));
                }
                bits.bits(s)?;
                // AC: run/size pairs until EOB or the 63rd coefficient (§F.2.2.2).
                let mut k = 1;
                while k < 64 {
                    let rs = bits.decode(ac, "an AC")?;
                    let (r, s) = (u32::from(rs >> 4), rs & 15);
                    if s == 0 {
                        if r == 15 {
                            k += 16;
                            continue;
                        }
                        break;
                    }
                    k += r;
                    if k > 63 {
                        return Err(format!(
                            "corrupt JPEG: an AC run past the block's 63rd coefficient near byte {}",
                            bits.pos
                        ));
                    }
                    bits.bits(s)?;
                    k += 1;
                }
            }
        }
    }
    let (code, at, skipped) = bits.next_marker()?;
    if skipped > 0 {
        return Err(extraneous(skipped, code, at));
    }
    Ok(at)
}

fn extraneous(skipped: usize, code: u8, at: usize) -> String {
    format!(
        "corrupt JPEG: {skipped} extraneous bytes before marker FF {code:02X} at byte {at} \
         (the scan's codes end before its data)"
    )
}
