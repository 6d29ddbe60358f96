//! The minimum kernels of the pruned search, with AVX2 versions when the CPU has it (any order of
//! a minimum gives the same number, so the keys stay bit for bit those of the plain programme).

/// The least `a[x] + b[x]` (∞ for none; a NaN sum never wins, as with `<`). Any order of a minimum
/// gives the same number, so AVX2 (`avx2`: the CPU has it) takes four at a time.
#[inline]
pub(super) fn min_of_sums(a: &[f64], b: &[f64], avx2: bool) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if avx2 {
        // SAFETY: the caller checked that the CPU supports AVX2.
        return unsafe { min_of_sums_avx2(a, b) };
    }
    let _ = avx2;
    a.iter().zip(b).fold(f64::INFINITY, |m, (x, y)| {
        let v = x + y;
        if v < m {
            v
        } else {
            m
        }
    })
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn min_of_sums_avx2(a: &[f64], b: &[f64]) -> f64 {
    use std::arch::x86_64::*;
    let len = a.len().min(b.len());
    let mut acc = _mm256_set1_pd(f64::INFINITY);
    let mut x = 0;
    while x + 4 <= len {
        // SAFETY: x + 4 ≤ the length of both slices; unaligned loads. min_pd(v, acc) is `v < acc ? v : acc`.
        unsafe {
            let v = _mm256_add_pd(_mm256_loadu_pd(a.as_ptr().add(x)), _mm256_loadu_pd(b.as_ptr().add(x)));
            acc = _mm256_min_pd(v, acc);
        }
        x += 4;
    }
    let mut lanes = [0.0; 4];
    // SAFETY: four f64 lanes into a four-element array.
    unsafe { _mm256_storeu_pd(lanes.as_mut_ptr(), acc) };
    lanes.into_iter().chain((x..len).map(|x| a[x] + b[x])).fold(f64::INFINITY, |m, v| if v < m { v } else { m })
}

/// `after[r·n + j] = min over b > j of lower[b·n + j]·scale + after[(r − 1)·n + b]` for every row
/// r ≥ 1 (row 0 given). Segment columns from the last frame back: a row's value at b is final once
/// every later column is in, and each column is read once (the order of a minimum does not change
/// it). `avx2`: the CPU has it.
pub(super) fn lower_to_go(lower: &[f64], after: &mut [f64], n: usize, scale: f64, avx2: bool) {
    let rows = after.len() / n;
    for b in (1..n).rev() {
        let column = &lower[b * n..b * n + b];
        for r in 1..rows {
            let (done, rest) = after.split_at_mut(r * n);
            let to_go = done[(r - 1) * n + b];
            if to_go == f64::INFINITY {
                continue;
            }
            let row = &mut rest[..b];
            #[cfg(target_arch = "x86_64")]
            if avx2 {
                // SAFETY: the caller checked that the CPU supports AVX2.
                unsafe { min_sums_avx2(row, column, scale, to_go) };
                continue;
            }
            let _ = avx2;
            for (o, &l) in row.iter_mut().zip(column) {
                let v = l * scale + to_go;
                *o = if v < *o { v } else { *o };
            }
        }
    }
}

/// `row[x] = min(column[x]·scale + to_go, row[x])` (as `<` picks), four at a time: plain stores of
/// `vminpd` (the compiler's own vectorisation chose masked stores, three times slower here).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn min_sums_avx2(row: &mut [f64], column: &[f64], scale: f64, to_go: f64) {
    use std::arch::x86_64::*;
    let len = row.len().min(column.len());
    let (s, t) = (_mm256_set1_pd(scale), _mm256_set1_pd(to_go));
    let mut x = 0;
    while x + 4 <= len {
        // SAFETY: x + 4 ≤ the length of both slices; unaligned loads and stores.
        unsafe {
            let l = _mm256_loadu_pd(column.as_ptr().add(x));
            let o = _mm256_loadu_pd(row.as_ptr().add(x));
            // min_pd(v, o) is `v < o ? v : o`.
            _mm256_storeu_pd(row.as_mut_ptr().add(x), _mm256_min_pd(_mm256_add_pd(_mm256_mul_pd(l, s), t), o));
        }
        x += 4;
    }
    for (o, &l) in row[x..len].iter_mut().zip(&column[x..len]) {
        let v = l * scale + to_go;
        *o = if v < *o { v } else { *o };
    }
}
