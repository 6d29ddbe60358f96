//! The C ABI of the runtime sampler, for engine plugins (Unity, Unreal, Godot). The header
//! `include/inbetween_ibk.h` is generated from this file by cbindgen (a test checks that the
//! committed header is the generated one).
//!
//! ```c
//! char err[256];
//! InbetweenIbk *clip = inbetween_ibk_open(bytes, len, err, sizeof err);  // bytes must outlive clip
//! uint32_t n = inbetween_ibk_num_joints(clip);
//! float rot[4 * n], tr[3 * n];
//! inbetween_ibk_sample(clip, 0.5, rot, tr, n);                            // 0 on success
//! inbetween_ibk_close(clip);
//! ```
//! Every function checks its pointers and sizes and returns an error code instead of crashing on
//! a null handle or a short buffer; none panics across the boundary.

use crate::{Clip, Context};
use std::os::raw::c_char;

/// An opened clip and its sampling context (one per playing instance; not thread-safe).
pub struct InbetweenIbk {
    clip: Clip<'static>,
    ctx: Context,
}

/// Success.
pub const INBETWEEN_IBK_OK: i32 = 0;
/// A null pointer where a handle or buffer was expected.
pub const INBETWEEN_IBK_NULL: i32 = 1;
/// A buffer of the wrong size (joint count).
pub const INBETWEEN_IBK_BUFFER: i32 = 2;

/// Copies `msg` (truncated, NUL-terminated) into `err` of `cap` bytes, when given.
unsafe fn write_err(err: *mut c_char, cap: usize, msg: &str) {
    if err.is_null() || cap == 0 {
        return;
    }
    let n = msg.len().min(cap - 1);
    // SAFETY: the caller gives `cap` writable bytes at `err`.
    unsafe {
        std::ptr::copy_nonoverlapping(msg.as_ptr(), err.cast::<u8>(), n);
        *err.add(n) = 0;
    }
}

/// Opens a version 4 `.ibk` file held in `len` bytes at `data`, without copying them: they must
/// stay valid and unchanged until [`inbetween_ibk_close`]. Returns NULL on failure and writes the
/// reason (NUL-terminated, at most `err_cap` bytes) into `err` when it is not NULL.
///
/// # Safety
/// `data` must point to `len` readable bytes and `err` (if not NULL) to `err_cap` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn inbetween_ibk_open(
    data: *const u8,
    len: usize,
    err: *mut c_char,
    err_cap: usize,
) -> *mut InbetweenIbk {
    if data.is_null() {
        unsafe { write_err(err, err_cap, "inbetween_ibk_open: data is NULL") };
        return std::ptr::null_mut();
    }
    // SAFETY: the caller keeps `len` bytes at `data` alive until close.
    let bytes: &'static [u8] = unsafe { std::slice::from_raw_parts(data, len) };
    let opened = std::panic::catch_unwind(|| Clip::open(bytes));
    match opened {
        Ok(Ok(clip)) => {
            let ctx = Context::new(&clip);
            Box::into_raw(Box::new(InbetweenIbk { clip, ctx }))
        }
        Ok(Err(e)) => {
            unsafe { write_err(err, err_cap, &e.to_string()) };
            std::ptr::null_mut()
        }
        Err(_) => {
            unsafe { write_err(err, err_cap, "inbetween_ibk_open: internal error") };
            std::ptr::null_mut()
        }
    }
}

/// Joints of an opened clip (0 for NULL).
///
/// # Safety
/// `clip` is NULL or a handle from [`inbetween_ibk_open`] not yet closed.
#[no_mangle]
pub unsafe extern "C" fn inbetween_ibk_num_joints(clip: *const InbetweenIbk) -> u32 {
    // SAFETY: see the function's contract.
    unsafe { clip.as_ref() }.map_or(0, |c| c.clip.num_joints() as u32)
}

/// Frames of an opened clip (0 for NULL).
///
/// # Safety
/// As [`inbetween_ibk_num_joints`].
#[no_mangle]
pub unsafe extern "C" fn inbetween_ibk_num_frames(clip: *const InbetweenIbk) -> u32 {
    unsafe { clip.as_ref() }.map_or(0, |c| c.clip.num_frames() as u32)
}

/// Seconds from the first frame to the last (0 for NULL).
///
/// # Safety
/// As [`inbetween_ibk_num_joints`].
#[no_mangle]
pub unsafe extern "C" fn inbetween_ibk_duration(clip: *const InbetweenIbk) -> f64 {
    unsafe { clip.as_ref() }.map_or(0.0, |c| c.clip.duration())
}

/// Parent of joint `joint` (-1 for a root, for NULL or for a joint out of range).
///
/// # Safety
/// As [`inbetween_ibk_num_joints`].
#[no_mangle]
pub unsafe extern "C" fn inbetween_ibk_parent(clip: *const InbetweenIbk, joint: u32) -> i32 {
    unsafe { clip.as_ref() }
        .and_then(|c| c.clip.joints().get(joint as usize))
        .and_then(|j| j.parent)
        .map_or(-1, |p| p as i32)
}

/// Samples the local pose at `time` seconds: `rotations` receives 4 floats per joint
/// (quaternion x, y, z, w), `translations` 3 per joint (the file's length unit); `joints` must
/// be [`inbetween_ibk_num_joints`]. Returns `INBETWEEN_IBK_OK`, `INBETWEEN_IBK_NULL` or
/// `INBETWEEN_IBK_BUFFER`. Allocates nothing.
///
/// # Safety
/// `clip` is a handle from [`inbetween_ibk_open`] not yet closed; `rotations` and `translations`
/// point to `4 × joints` and `3 × joints` writable floats.
#[no_mangle]
pub unsafe extern "C" fn inbetween_ibk_sample(
    clip: *mut InbetweenIbk,
    time: f64,
    rotations: *mut f32,
    translations: *mut f32,
    joints: u32,
) -> i32 {
    // SAFETY: see the function's contract.
    let Some(h) = (unsafe { clip.as_mut() }) else { return INBETWEEN_IBK_NULL };
    if rotations.is_null() || translations.is_null() {
        return INBETWEEN_IBK_NULL;
    }
    let n = h.clip.num_joints();
    if joints as usize != n {
        return INBETWEEN_IBK_BUFFER;
    }
    // SAFETY: the caller gives 4n and 3n writable floats; [f32; 4] and [f32; 3] have the
    // alignment of f32.
    let (r, t) = unsafe {
        (
            std::slice::from_raw_parts_mut(rotations.cast::<[f32; 4]>(), n),
            std::slice::from_raw_parts_mut(translations.cast::<[f32; 3]>(), n),
        )
    };
    if h.clip.sample(&mut h.ctx, time, r, t).is_err() {
        return INBETWEEN_IBK_BUFFER;
    }
    INBETWEEN_IBK_OK
}

/// Closes a handle (NULL is ignored). The file's bytes may be freed afterwards.
///
/// # Safety
/// `clip` is NULL or a handle from [`inbetween_ibk_open`], closed once.
#[no_mangle]
pub unsafe extern "C" fn inbetween_ibk_close(clip: *mut InbetweenIbk) {
    if !clip.is_null() {
        // SAFETY: made by Box::into_raw in open, closed once.
        drop(unsafe { Box::from_raw(clip) });
    }
}
