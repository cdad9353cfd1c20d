//! The designer's parallel loops (the Monte Carlo's draws, the sweep's
//! sample periods): on rayon's threads with the `parallel` feature, in
//! order without it. The answers are the same either way (every item is
//! computed from its index alone, and merged associatively), so a firmware
//! build, which designs and emits but never analyses, compiles no thread
//! pool.

/// `f(0) … f(n − 1)` merged by `merge` from `identity()`; the first error
/// found ends the loop (with threads, any error found first).
pub(crate) fn try_map_reduce<T, E>(
    n: usize,
    f: impl Fn(usize) -> Result<T, E> + Sync + Send,
    identity: impl Fn() -> T + Sync + Send,
    merge: impl Fn(T, T) -> T + Sync + Send,
) -> Result<T, E>
where
    T: Send,
    E: Send,
{
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        (0..n)
            .into_par_iter()
            .map(f)
            .try_reduce(identity, |a, b| Ok(merge(a, b)))
    }
    #[cfg(not(feature = "parallel"))]
    {
        (0..n).try_fold(identity(), |acc, k| Ok(merge(acc, f(k)?)))
    }
}

/// `f` of every item, in the items' order.
pub(crate) fn map<T: Sync, U: Send>(items: &[T], f: impl Fn(&T) -> U + Sync + Send) -> Vec<U> {
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        items.par_iter().map(f).collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        items.iter().map(f).collect()
    }
}
