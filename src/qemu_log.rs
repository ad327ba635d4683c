//! `defmt` global logger for the QEMU images: each frame is encoded into a
//! RAM buffer and written with one semihosting call when the frame ends.
//!
//! `defmt-semihosting` issues a semihosting call per encoder chunk (often a
//! single byte), which costs the guest ~2,000 instructions per telemetry
//! record; on a board, RTT's cost is a copy into a ring buffer. Buffering
//! the frame gives the emulated firmware the same cost profile as the real
//! one, so the measured per-tick budget means the same thing on both.
//! Frames longer than the buffer are written in pieces (the stream stays
//! valid). The semihosting write itself is done by QEMU, outside the guest.

use core::cell::UnsafeCell;
use core::sync::atomic::{AtomicBool, Ordering};
use cortex_m_semihosting::hio::HostStream;

/// Buffer for one frame (a telemetry frame is ~70 bytes: the record's 48,
/// the time, the format strings' indices).
const BUFFER: usize = 256;

#[defmt::global_logger]
struct Logger;

/// State touched only between `acquire` and `release`, inside a critical
/// section, with `TAKEN` guarding against re-entry.
struct Cell<T>(UnsafeCell<T>);

// SAFETY: see the type's documentation.
unsafe impl<T> Sync for Cell<T> {}

struct Buffer {
    bytes: [u8; BUFFER],
    len: usize,
    stdout: Option<HostStream>,
}

static TAKEN: AtomicBool = AtomicBool::new(false);
static RESTORE: Cell<critical_section::RestoreState> = Cell(UnsafeCell::new(critical_section::RestoreState::invalid()));
static ENCODER: Cell<defmt::Encoder> = Cell(UnsafeCell::new(defmt::Encoder::new()));
static OUT: Cell<Buffer> = Cell(UnsafeCell::new(Buffer {
    bytes: [0; BUFFER],
    len: 0,
    stdout: None,
}));

/// Writes the buffered bytes to the host (the handle is opened once).
fn flush_buffer(out: &mut Buffer) {
    if out.len == 0 {
        return;
    }
    if out.stdout.is_none() {
        out.stdout = cortex_m_semihosting::hio::hstdout().ok();
    }
    if let (Some(h), Some(frame)) = (out.stdout.as_mut(), out.bytes.get(..out.len)) {
        let _ = h.write_all(frame);
    }
    out.len = 0;
}

/// Appends encoded bytes. The chunks are a few bytes long (a float is
/// four): the common case, a chunk that fits, is one check and a tight copy
/// with one length update; only a full buffer takes the per-byte path.
fn push(bytes: &[u8]) {
    // SAFETY: only called by the encoder inside acquire..release.
    let out = unsafe { &mut *OUT.0.get() };
    let start = out.len;
    if let Some(dst) = out.bytes.get_mut(start..start + bytes.len()) {
        // Byte by byte, volatile so that the loop is not turned into a call
        // of `memcpy`, whose set-up costs more than the few bytes of a chunk
        // (the encoder's chunks are runs of at most a few bytes).
        for (d, s) in dst.iter_mut().zip(bytes) {
            // SAFETY: `d` is a valid, exclusive reference into the buffer.
            unsafe { core::ptr::write_volatile(d, *s) };
        }
        out.len = start + bytes.len();
        return;
    }
    for &b in bytes {
        if out.len >= BUFFER {
            flush_buffer(out);
        }
        // Always `Some` (`len < BUFFER` here); `get_mut` keeps the logger,
        // which the tick's telemetry runs through, free of panic paths.
        if let Some(slot) = out.bytes.get_mut(out.len) {
            *slot = b;
            out.len += 1;
        }
    }
}

unsafe impl defmt::Logger for Logger {
    fn acquire() {
        // SAFETY: paired with the `release` below.
        let restore = unsafe { critical_section::acquire() };
        // A load and a store, not `swap`: the Cortex-M0 has no atomic
        // read-modify-write, and inside the critical section none is needed.
        if TAKEN.load(Ordering::Relaxed) {
            // Re-entered (a fault or panic while logging): the frame in
            // progress is lost; end the run rather than interleave frames.
            crate::qemu::exit(false);
        }
        TAKEN.store(true, Ordering::Relaxed);
        // SAFETY: we hold the critical section and `TAKEN`.
        unsafe {
            *RESTORE.0.get() = restore;
            (*ENCODER.0.get()).start_frame(push);
        }
    }

    unsafe fn flush() {
        // SAFETY: defmt calls this between acquire and release.
        flush_buffer(unsafe { &mut *OUT.0.get() });
    }

    unsafe fn release() {
        // SAFETY: between acquire and release; the restore state came from
        // `acquire`.
        unsafe {
            (*ENCODER.0.get()).end_frame(push);
            flush_buffer(&mut *OUT.0.get());
            let restore = *RESTORE.0.get();
            TAKEN.store(false, Ordering::Relaxed);
            critical_section::release(restore);
        }
    }

    unsafe fn write(bytes: &[u8]) {
        // SAFETY: defmt calls this between acquire and release.
        unsafe { (*ENCODER.0.get()).write(bytes, push) };
    }
}
