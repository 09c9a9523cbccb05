//! Thinning a sequence for display: a path of thousands of poses drawn with a few hundred.

/// At most `max` items of `items`, evenly spread, the first and the last always kept (for
/// `max` ≥ 2; below that, the first `max`).
pub fn downsample<T: Clone>(items: &[T], max: usize) -> Vec<T> {
    if items.len() <= max || max < 2 {
        return items.iter().take(max).cloned().collect();
    }
    let last = items.len() - 1;
    (0..max).map(|i| items[i * last / (max - 1)].clone()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn downsampling_keeps_the_ends_and_the_count() {
        let v: Vec<usize> = (0..1001).collect();
        // 1000 intervals in 4: every 250th.
        assert_eq!(downsample(&v, 5), vec![0, 250, 500, 750, 1000]);
        assert_eq!(downsample(&v[..3], 5), vec![0, 1, 2]);
        assert_eq!(downsample(&v, 1), vec![0]);
        assert!(downsample(&v, 0).is_empty());
        // 7 items in 3: indices 0, 6·1/2 = 3, 6.
        assert_eq!(downsample(&v[..7], 3), vec![0, 3, 6]);
    }
}
