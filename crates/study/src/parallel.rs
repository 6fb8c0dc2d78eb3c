//! Independent jobs on worker threads, their results handed back in the jobs' order as
//! they complete: what the sweeps (`tradeoff`, `refine --sweep`, the `fit` search's
//! candidates) run on, so that their output is the same at any thread count.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;

/// What [`ordered`] tells the calling thread as the jobs go.
pub enum Event<R> {
    /// Job `index` was started (on some worker).
    Started(usize),
    /// Job `index` is done, and so is every job before it: its result, in order.
    Done(usize, R),
}

/// Runs `job(0) … job(count − 1)` on `threads` threads (0: one per core; the calling
/// thread is one of them when `threads` is 1, and only waits otherwise), calling
/// `report` on the calling thread with each job's start and, in index order, each
/// result as soon as it and every earlier one are done. Jobs are taken in index order;
/// after a job fails no new one is started, and the error returned is that of the first
/// failing job in index order (every earlier job was started before it, so it is the
/// one a single thread would have met), the results before it having been reported.
pub fn ordered<R: Send, E: Send>(
    count: usize,
    threads: usize,
    job: impl Fn(usize) -> Result<R, E> + Sync,
    mut report: impl FnMut(Event<R>),
) -> Result<(), E> {
    let threads = cwisim_scene::budget::resolve_threads(threads).min(count.max(1));
    if threads <= 1 {
        for k in 0..count {
            report(Event::Started(k));
            report(Event::Done(k, job(k)?));
        }
        return Ok(());
    }
    let next = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    std::thread::scope(|scope| {
        let (tx, rx) = mpsc::channel::<(usize, Option<Result<R, E>>)>();
        for _ in 0..threads {
            let tx = tx.clone();
            let (next, stop, job) = (&next, &stop, &job);
            scope.spawn(move || loop {
                if stop.load(Ordering::SeqCst) {
                    return;
                }
                let k = next.fetch_add(1, Ordering::SeqCst);
                if k >= count {
                    return;
                }
                if tx.send((k, None)).is_err() {
                    return;
                }
                let result = job(k);
                if result.is_err() {
                    stop.store(true, Ordering::SeqCst);
                }
                if tx.send((k, Some(result))).is_err() {
                    return;
                }
            });
        }
        drop(tx);
        // results that came early, until every job before them is in
        let mut waiting: Vec<Option<Result<R, E>>> = (0..count).map(|_| None).collect();
        let mut due = 0;
        let mut failed: Option<E> = None;
        for (k, message) in rx {
            match message {
                None => {
                    if failed.is_none() {
                        report(Event::Started(k));
                    }
                }
                Some(result) => waiting[k] = Some(result),
            }
            while failed.is_none() && due < count {
                match waiting[due].take() {
                    Some(Ok(r)) => {
                        report(Event::Done(due, r));
                        due += 1;
                    }
                    Some(Err(e)) => {
                        stop.store(true, Ordering::SeqCst);
                        failed = Some(e);
                    }
                    None => break,
                }
            }
        }
        match failed {
            Some(e) => Err(e),
            None => Ok(()),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(count: usize, threads: usize, fail: Option<usize>) -> (Vec<usize>, Result<(), usize>) {
        let mut done = Vec::new();
        let result = ordered(
            count,
            threads,
            |k| {
                // later jobs finish first
                std::thread::sleep(std::time::Duration::from_millis(((count - k) % 4) as u64));
                match fail {
                    Some(f) if k >= f && k % 2 == f % 2 => Err(k),
                    _ => Ok(k * k),
                }
            },
            |event| {
                if let Event::Done(k, r) = event {
                    assert_eq!(r, k * k);
                    done.push(k);
                }
            },
        );
        (done, result)
    }

    #[test]
    fn results_come_in_order_at_any_thread_count() {
        for threads in [1, 2, 3, 8] {
            let (done, result) = run(23, threads, None);
            assert_eq!(done, (0..23).collect::<Vec<_>>(), "{threads}");
            assert_eq!(result, Ok(()));
        }
        assert_eq!(run(0, 3, None), (Vec::new(), Ok(())));
    }

    #[test]
    fn the_first_failure_in_order_is_returned_after_every_earlier_result() {
        for threads in [1, 2, 3, 8] {
            let (done, result) = run(23, threads, Some(9));
            assert_eq!(done, (0..9).collect::<Vec<_>>(), "{threads}");
            assert_eq!(result, Err(9), "{threads}");
        }
    }
}
