//! snapshot — FMU states (fmi2GetFMUstate & co.) and their byte format.
//!
//! An fmi2FMUstate is a `Box<Snapshot>`: a tag and a complete copy of the
//! instance's [`Sim`] (the loaded tyre is shared through an `Arc`).
//!
//! Serialized format, little-endian, version 2:
//! ```text
//! magic     8 bytes  "TYREKIT\x01"... see MAGIC
//! version   u32      FORMAT_VERSION
//! length    u64      total length in bytes, header and checksum included
//! guid      u64      FNV-1a of the GUID: a state only fits the interface it came from
//! tyre      u64      FNV-1a of the bytes of the tyre file the state belongs to
//! payload   phase u8, time f64, start f64, stop flag u8 + f64,
//!           reals N×f64, integers N×i32, booleans N×u8 (0/1),
//!           strings N×(u32 length + UTF-8 bytes) except tyre_file,
//!           transient state N_STATES×f64
//! checksum  u64      FNV-1a of everything before it
//! ```
//! A state never carries a path and deserializing never opens a file (a
//! checksum anyone can recompute protects against accidents, not against a
//! crafted buffer: the defence is that a state cannot name files). It carries
//! the hash of the tyre content instead and is refused unless that is the
//! tyre the instance has loaded (its current `tyre_file`, or the packaged
//! resources/tyre.tir); `tyre_file` is restored as the matching one's value.
//! Must never: read outside the buffer, accept a buffer that fails any check,
//! or dereference a state pointer without checking its tag.

use super::instance::{derive, Instance, Phase, Sim};
use super::vars::{self, string, Values};
use crate::transient::N_STATES;
use std::ffi::CString;

/// First bytes of every serialized state.
pub const MAGIC: [u8; 8] = *b"TKFMUST\x01";
/// Version of the byte format.
pub const FORMAT_VERSION: u32 = 2;
/// Tag of a live snapshot.
pub const SNAPSHOT_TAG: u64 = 0x5459_5245_5354_4154; // "TYRESTAT"

/// What an fmi2FMUstate points to.
#[derive(Clone, Debug)]
pub struct Snapshot {
    /// [`SNAPSHOT_TAG`] while the state lives; 0 once it is freed.
    pub tag: u64,
    /// The saved simulation (phase, time, values, model state, tyre).
    pub sim: Sim,
    /// The instance that created it (only it may free it; fmi2FreeInstance
    /// frees every state its instance still owns).
    pub owner: usize,
}

/// FNV-1a 64.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

const HEADER: usize = 8 + 4 + 8 + 8 + 8;

/// Serialize a state.
pub fn serialize(sim: &Sim) -> Vec<u8> {
    let mut b = Vec::with_capacity(1024);
    b.extend_from_slice(&MAGIC);
    b.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    b.extend_from_slice(&0u64.to_le_bytes()); // length, patched below
    b.extend_from_slice(&fnv1a(vars::GUID.as_bytes()).to_le_bytes());
    b.extend_from_slice(&sim.loaded.hash.to_le_bytes());
    b.push(sim.phase as u8);
    b.extend_from_slice(&sim.time.to_le_bytes());
    b.extend_from_slice(&sim.start_time.to_le_bytes());
    b.push(u8::from(sim.stop_time.is_some()));
    b.extend_from_slice(&sim.stop_time.unwrap_or(0.0).to_le_bytes());
    for x in &sim.values.reals {
        b.extend_from_slice(&x.to_le_bytes());
    }
    for x in &sim.values.integers {
        b.extend_from_slice(&x.to_le_bytes());
    }
    for x in &sim.values.booleans {
        b.push(u8::from(*x));
    }
    for (i, s) in sim.values.strings.iter().enumerate() {
        if i == string::TYRE_FILE {
            continue;
        }
        let bytes = s.as_bytes();
        b.extend_from_slice(&(bytes.len() as u32).to_le_bytes());
        b.extend_from_slice(bytes);
    }
    for x in &sim.model.state.x {
        b.extend_from_slice(&x.to_le_bytes());
    }
    let total = (b.len() + 8) as u64;
    b[12..20].copy_from_slice(&total.to_le_bytes());
    let sum = fnv1a(&b);
    b.extend_from_slice(&sum.to_le_bytes());
    b
}

/// Bounds-checked reader.
struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self.at.checked_add(n).filter(|e| *e <= self.b.len());
        match end {
            Some(e) => {
                let s = &self.b[self.at..e];
                self.at = e;
                Ok(s)
            }
            None => Err(format!(
                "serialized FMU state truncated at byte {} (wanted {n} more of {})",
                self.at,
                self.b.len()
            )),
        }
    }
    fn arr<const N: usize>(&mut self) -> Result<[u8; N], String> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.take(N)?);
        Ok(a)
    }
    fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }
    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.arr()?))
    }
    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.arr()?))
    }
    fn i32(&mut self) -> Result<i32, String> {
        Ok(i32::from_le_bytes(self.arr()?))
    }
    fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_le_bytes(self.arr()?))
    }
}

/// Check and decode a serialized state for `inst` (the tyre is resolved through
/// the instance: reused when it is the loaded one, else reloaded).
pub fn deserialize(inst: &Instance, bytes: &[u8]) -> Result<Sim, String> {
    if bytes.len() < HEADER + 8 {
        return Err(format!(
            "serialized FMU state has {} bytes, fewer than the {}-byte header",
            bytes.len(),
            HEADER + 8
        ));
    }
    let mut r = Reader { b: bytes, at: 0 };
    if r.arr::<8>()? != MAGIC {
        return Err("not a TyreKit FMU state (bad magic bytes)".into());
    }
    let version = r.u32()?;
    if version != FORMAT_VERSION {
        return Err(format!(
            "FMU state format version {version}, this binary reads version {FORMAT_VERSION}"
        ));
    }
    let len = r.u64()?;
    if len != bytes.len() as u64 {
        return Err(format!(
            "FMU state says it has {len} bytes, the buffer has {}",
            bytes.len()
        ));
    }
    if r.u64()? != fnv1a(vars::GUID.as_bytes()) {
        return Err("FMU state was saved by an FMU with another interface (GUID differs)".into());
    }
    let tyre_hash = r.u64()?;
    let body = &bytes[..bytes.len() - 8];
    let sum = u64::from_le_bytes(bytes[bytes.len() - 8..].try_into().unwrap_or([0; 8]));
    if fnv1a(body) != sum {
        return Err("FMU state checksum mismatch (corrupted buffer)".into());
    }
    let phase = Phase::from_u8(r.u8()?).ok_or("FMU state has an invalid FMI state")?;
    if phase == Phase::Fatal {
        return Err("FMU state was saved in the fatal state".into());
    }
    let time = r.f64()?;
    let start_time = r.f64()?;
    let has_stop = r.u8()?;
    let stop = r.f64()?;
    if has_stop > 1 || !time.is_finite() || !start_time.is_finite() || !stop.is_finite() {
        return Err("FMU state has invalid times".into());
    }
    let mut values = Values::start();
    for x in values.reals.iter_mut() {
        *x = r.f64()?;
        if !x.is_finite() {
            return Err("FMU state holds a non-finite Real".into());
        }
    }
    for x in values.integers.iter_mut() {
        *x = r.i32()?;
    }
    for x in values.booleans.iter_mut() {
        *x = match r.u8()? {
            0 => false,
            1 => true,
            _ => return Err("FMU state holds an invalid Boolean".into()),
        };
    }
    for (i, s) in values.strings.iter_mut().enumerate() {
        if i == string::TYRE_FILE {
            continue;
        }
        let n = r.u32()? as usize;
        let text = std::str::from_utf8(r.take(n)?)
            .map_err(|_| "FMU state holds a string that is not UTF-8".to_string())?;
        *s = CString::new(text).map_err(|_| "FMU state holds a string with NUL".to_string())?;
    }
    let mut x = [0.0; N_STATES];
    for v in x.iter_mut() {
        *v = r.f64()?;
        if !v.is_finite() {
            return Err("FMU state holds a non-finite dynamic state".into());
        }
    }
    if r.at != bytes.len() - 8 {
        return Err(format!(
            "FMU state has {} unexpected bytes",
            bytes.len() - 8 - r.at
        ));
    }
    let loaded = if tyre_hash == inst.sim.loaded.hash {
        inst.sim.loaded.clone()
    } else if tyre_hash == inst.default_tyre.hash {
        inst.default_tyre.clone()
    } else {
        return Err(format!(
            "FMU state belongs to another tyre (content hash {tyre_hash:016x}; this instance has \
             {:016x} loaded from {}): set the same tyre_file first; a state never names a file",
            inst.sim.loaded.hash,
            inst.sim.loaded.path.display()
        ));
    };
    values.strings[string::TYRE_FILE] =
        CString::new(loaded.key.as_str()).map_err(|_| "tyre_file with NUL".to_string())?;
    let d = derive(&values, &loaded.tyre)?;
    let mut model = crate::transient::TransientModel::with_options(d.config, d.options);
    model.state.x = x;
    Ok(Sim {
        phase,
        time,
        start_time,
        stop_time: (has_stop == 1).then_some(stop),
        values,
        model,
        mirror: d.mirror,
        loaded,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fmi::logging::Logger;

    /// An instance of the built-in tyre and its resources folder (removed
    /// when the guard drops).
    fn instance() -> (Box<Instance>, tempfile::TempDir) {
        let dir = tempfile::Builder::new()
            .prefix("tyrekit-snapshot-")
            .tempdir()
            .unwrap();
        crate::tir::TyreParams::builtin()
            .write(&dir.path().join("tyre.tir"))
            .unwrap();
        let inst = Instance::new(
            Logger::new(None, "t", false),
            Some(dir.path().to_str().unwrap()),
        )
        .map_err(|(_, e)| e)
        .unwrap();
        (inst, dir)
    }

    #[test]
    fn round_trip_is_exact() {
        let (mut inst, _dir) = instance();
        inst.sim.phase = Phase::StepComplete;
        inst.sim.values.reals[crate::fmi::vars::real::VY] = 0.7;
        inst.do_step(0.0, 1e-3).unwrap();
        inst.sim.model.state.x = [1.0, -2.0, 3.5, 0.0, 1e-300, -0.0, 7.0, 8.0];
        let bytes = serialize(&inst.sim);
        let back = deserialize(&inst, &bytes).unwrap();
        assert_eq!(back.values, inst.sim.values);
        assert_eq!(back.model.state, inst.sim.model.state);
        assert_eq!(back.time, inst.sim.time);
        assert_eq!(back.phase, inst.sim.phase);
        assert_eq!(serialize(&back), bytes);
    }

    #[test]
    fn every_truncation_and_byte_flip_is_refused() {
        let (inst, _dir) = instance();
        let bytes = serialize(&inst.sim);
        for n in 0..bytes.len() {
            assert!(deserialize(&inst, &bytes[..n]).is_err(), "truncated to {n}");
        }
        for i in 0..bytes.len() {
            let mut b = bytes.clone();
            b[i] ^= 0x5a;
            assert!(deserialize(&inst, &b).is_err(), "byte {i} flipped");
        }
    }
}
