//! Zeroed buffers for level data, backed by transparent huge pages where
//! the OS offers them.
//!
//! A fresh level is written once, front to back. With 4 KiB pages every
//! first write faults, and on Linux each fault (with its memory-cgroup
//! charge) costs about a microsecond: 16 Ki faults, some 20 ms, for the
//! 64 MiB level 1 of a 4096² RGBA f32 texture, as much as the filtering
//! itself. Linux commonly runs transparent huge pages in `madvise` mode,
//! so buffers of several MiB are advised `MADV_HUGEPAGE` before their
//! first touch: one fault per 2 MiB instead of 512. The advice changes
//! nothing else; where it is refused or unavailable the buffer simply
//! keeps small pages.

/// Buffers smaller than this keep the allocator's default.
const HUGE_MIN_BYTES: usize = 4 << 20;

/// `n` zero values, from zeroed memory (no write pass), advised for huge
/// pages when large.
pub(crate) fn zeroed<T: bytemuck::Zeroable>(n: usize) -> Vec<T> {
    let v: Vec<T> = bytemuck::zeroed_vec(n);
    let bytes = std::mem::size_of_val(v.as_slice());
    if bytes >= HUGE_MIN_BYTES {
        advise_huge_pages(v.as_ptr().cast(), bytes);
    }
    v
}

#[cfg(target_os = "linux")]
fn advise_huge_pages(ptr: *const u8, len: usize) {
    const PAGE: usize = 4096;
    let start = (ptr as usize).next_multiple_of(PAGE);
    let end = (ptr as usize + len) / PAGE * PAGE;
    if end > start {
        #[allow(unsafe_code)]
        // SAFETY: MADV_HUGEPAGE is advice only: it changes neither the
        // contents nor the protection of the range, which is page-aligned
        // and lies inside the live allocation the caller holds. A failure
        // (e.g. THP compiled out) is harmless and ignored.
        unsafe {
            libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn advise_huge_pages(_ptr: *const u8, _len: usize) {}

/// Fault in the pages of the `len` bytes at `ptr`, writable, without
/// reading or writing them (`MADV_POPULATE_WRITE`): the OS clears fresh
/// pages as it maps them, which costs as much as the work that later
/// fills them (a gigabyte of first touches took about 2 s of CPU on the
/// project's VM). Run on an idle core while another thread fills the
/// buffer front to back, it moves that cost off the filling thread. Pages
/// already present are left as they are, so it may run concurrently with
/// writes to the same buffer. A kernel without the advice (before Linux
/// 5.14) refuses it, and the pages fault on first write as before.
#[cfg_attr(not(feature = "io"), allow(dead_code))] // the file pipeline's
pub(crate) fn populate(ptr: *const u8, len: usize) {
    #[cfg(target_os = "linux")]
    {
        const PAGE: usize = 4096;
        // 64 MiB per call, so a buffer being filled from its front is
        // populated from its front too.
        const STEP: usize = 64 << 20;
        let start = (ptr as usize).next_multiple_of(PAGE);
        let end = (ptr as usize + len) / PAGE * PAGE;
        let mut at = start;
        while at < end {
            let n = STEP.min(end - at);
            #[allow(unsafe_code)]
            // SAFETY: the range is page-aligned and inside the live
            // allocation the caller holds; the advice maps pages without
            // accessing their bytes (it does not change what the buffer
            // holds). A failure is harmless: stop advising.
            let r = unsafe { libc::madvise(at as *mut libc::c_void, n, libc::MADV_POPULATE_WRITE) };
            if r != 0 {
                return;
            }
            at += n;
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = (ptr, len);
}

#[cfg(test)]
mod tests {
    #[test]
    fn zeroed_buffers_are_zero_at_every_size() {
        for n in [0usize, 1, 4095, 1 << 20, (4 << 20) + 3] {
            let v: Vec<f32> = super::zeroed(n);
            assert_eq!(v.len(), n);
            assert!(v.iter().all(|&x| x.to_bits() == 0));
            let b: Vec<u8> = super::zeroed(n);
            assert!(b.iter().all(|&x| x == 0));
        }
    }
}
