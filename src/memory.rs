//! Frame-sized buffers and the pages behind them.
//!
//! A 1920×1080 frame keeps about 16 MB of depth and colour. With 4 KiB pages that is
//! some 4000 pages, more than a second-level TLB of 1–2 thousand entries holds, and
//! triangles touch a new row of pixels every 7.5 KB: without huge pages, depth tests
//! wait on page walks. Under the `madvise` policy Linux backs memory with 2 MiB
//! transparent huge pages only where asked (under `always` it does anyway), and only
//! for pages not yet touched, so the advice is given when a buffer grows, before it
//! is filled.

/// Buffers smaller than this are left alone: they cannot hold more than one aligned
/// 2 MiB page and fit in the TLB anyway (every terminal-sized frame is far below).
pub const HUGE_PAGE_MIN_BYTES: usize = 4 << 20;

/// Makes room for `len` elements in `v` (capacity only, contents unchanged), asking
/// for huge pages behind a new allocation of at least [`HUGE_PAGE_MIN_BYTES`]. Does
/// nothing when the capacity suffices, so a steady frame loop never allocates here;
/// but an empty buffer of at least [`HUGE_PAGE_MIN_BYTES`] that holds four times the
/// room asked for is given back first (a window made much smaller after a large one).
pub fn reserve_frame<T>(v: &mut Vec<T>, len: usize) {
    let oversized =
        v.capacity() * size_of::<T>() >= HUGE_PAGE_MIN_BYTES && v.capacity() / 4 >= len.max(1);
    if v.is_empty() && oversized {
        *v = Vec::new();
    }
    if v.capacity() >= len {
        return;
    }
    if v.is_empty() {
        // A fresh allocation rather than a reallocation, which could move the old
        // (already touched, small) pages into the new buffer.
        *v = Vec::new();
    }
    v.reserve_exact(len - v.len());
    advise_huge_pages(v);
}

/// Refills `v` with `len` copies of `value`, through [`reserve_frame`]: a per-cell or
/// per-sample buffer sized anew for a frame.
pub fn refill<T: Clone>(v: &mut Vec<T>, len: usize, value: T) {
    v.clear();
    reserve_frame(v, len);
    v.resize(len, value);
}

/// Asks the kernel to back `v`'s whole allocation with transparent huge pages. Only
/// advice: failure (no THP in the kernel, or a policy of `never`) changes nothing
/// but speed, so it is ignored.
fn advise_huge_pages<T>(v: &mut Vec<T>) {
    let bytes = v.capacity() * size_of::<T>();
    if bytes < HUGE_PAGE_MIN_BYTES {
        return;
    }
    #[cfg(target_os = "linux")]
    {
        const PAGE: usize = 4096;
        let start = v.as_mut_ptr() as usize;
        let first = start.next_multiple_of(PAGE);
        let end = (start + bytes) / PAGE * PAGE;
        if end > first {
            // SAFETY: the range lies inside `v`'s allocation (rounded inwards to whole
            // pages), which this process owns; MADV_HUGEPAGE changes how its pages are
            // backed, never their contents or validity.
            unsafe {
                libc::madvise(first as *mut libc::c_void, end - first, libc::MADV_HUGEPAGE);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reserve_keeps_contents_and_reaches_the_length() {
        for (start, len) in [(0usize, 10usize), (5, 3), (7, 7), (3, 1 << 21)] {
            let mut v: Vec<u32> = (0..start as u32).collect();
            reserve_frame(&mut v, len);
            assert!(v.capacity() >= len);
            assert_eq!(v, (0..start as u32).collect::<Vec<_>>());
        }
    }

    #[test]
    fn a_much_smaller_frame_gives_the_room_back() {
        let big = HUGE_PAGE_MIN_BYTES / 4;
        let mut v: Vec<u32> = Vec::new();
        reserve_frame(&mut v, big);
        reserve_frame(&mut v, big / 2);
        assert!(v.capacity() >= big, "half the room is kept");
        reserve_frame(&mut v, big / 8);
        assert!(v.capacity() < big / 2, "an eighth gives it back");
        // Contents are never dropped, and small buffers are left alone.
        let mut w: Vec<u32> = vec![7; 3];
        w.reserve_exact(big);
        reserve_frame(&mut w, 4);
        assert!(w.capacity() >= big && w == [7, 7, 7]);
        let mut small: Vec<u32> = Vec::with_capacity(1000);
        reserve_frame(&mut small, 10);
        assert_eq!(small.capacity(), 1000);
    }

    #[test]
    fn a_sufficient_capacity_is_not_reallocated() {
        let mut v: Vec<f32> = Vec::with_capacity(100);
        let p = v.as_ptr();
        reserve_frame(&mut v, 100);
        assert_eq!(v.as_ptr(), p);
    }

    /// The mapping holding a large buffer carries the huge-page advice (`hg` in its
    /// VmFlags), wherever the kernel has transparent huge pages at all.
    #[cfg(target_os = "linux")]
    #[test]
    fn large_buffers_are_advised_to_use_huge_pages() {
        if !std::path::Path::new("/sys/kernel/mm/transparent_hugepage").exists() {
            return;
        }
        let mut v: Vec<f32> = Vec::new();
        reserve_frame(&mut v, 1920 * 1080);
        let mid = v.as_ptr() as usize + v.capacity() * 2;
        let smaps = std::fs::read_to_string("/proc/self/smaps").expect("smaps");
        let mut inside = false;
        let mut flags = None;
        for line in smaps.lines() {
            if let Some((range, _)) = line.split_once(' ')
                && let Some((a, b)) = range.split_once('-')
                && let (Ok(a), Ok(b)) = (usize::from_str_radix(a, 16), usize::from_str_radix(b, 16))
            {
                inside = (a..b).contains(&mid);
            } else if inside && let Some(f) = line.strip_prefix("VmFlags:") {
                flags = Some(f.split_whitespace().map(str::to_owned).collect::<Vec<_>>());
            }
        }
        let flags = flags.expect("the buffer's mapping is listed");
        assert!(flags.iter().any(|f| f == "hg"), "{flags:?}");
    }
}
