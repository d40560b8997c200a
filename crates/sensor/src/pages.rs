//! Memory the kernel may back with huge pages (2 MiB): a large buffer then takes hundreds of
//! page faults instead of tens of thousands, and a walk over it that jumps from one end to the
//! other misses the TLB far less often.

/// An empty vector with room for `capacity` elements, which the kernel is asked to back with
/// huge pages where it can (advice: nothing depends on whether it does).
pub(crate) fn huge_vec<T>(capacity: usize) -> Vec<T> {
    let mut v = Vec::with_capacity(capacity);
    advise(&mut v);
    v
}

#[cfg(target_os = "linux")]
fn advise<T>(v: &mut Vec<T>) {
    const HUGE: usize = 2 << 20;
    let spare = v.spare_capacity_mut();
    let (start, len) = (spare.as_mut_ptr() as usize, size_of_val(spare));
    let (from, to) = (start.next_multiple_of(HUGE), (start + len) / HUGE * HUGE);
    if to > from {
        // SAFETY: advice on memory the vector owns and has not yet written; the kernel may
        // ignore it
        unsafe { libc::madvise(from as *mut libc::c_void, to - from, libc::MADV_HUGEPAGE) };
    }
}

#[cfg(not(target_os = "linux"))]
fn advise<T>(_: &mut Vec<T>) {}
