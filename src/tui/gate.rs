//! The render gate: how many viewers of one process draw at once, and who goes next.
//!
//! A server with many watchers has a fixed number of slots (a total budget of
//! frames in flight, one per core by default). When a slot frees, the waiting frame
//! whose watcher has used the least rendering time goes first, so watchers share
//! the CPU by time, not by frames: a watcher of a 200×60 terminal, whose frames cost
//! four times an 80×24 one's, gets a quarter of the frames when the CPU is short,
//! and none can take more than its share by asking more often. A watcher that comes
//! back from idling starts level with the others (its account is raised to the time
//! of the frames admitted meanwhile), so it cannot save up a burst.

use std::cell::Cell;
use std::sync::{Condvar, Mutex, MutexGuard};
use std::time::Instant;

/// The slots and the queue.
#[derive(Debug)]
pub struct RenderGate {
    state: Mutex<State>,
    turn: Condvar,
}

#[derive(Debug)]
struct State {
    slots: usize,
    busy: usize,
    /// Waiting frames: (their account's time, arrival), the least first.
    waiting: Vec<(u64, u64)>,
    arrivals: u64,
    /// The account time of the latest frame admitted: where a returning or new
    /// account starts.
    floor: u64,
}

/// One viewer's use of the gate: the rendering time it has been charged, in
/// nanoseconds. Owned by the viewer's thread.
#[derive(Debug, Default)]
pub struct Account {
    used: Cell<u64>,
}

impl Account {
    /// The rendering time charged so far (raised to the gate's floor when it came
    /// back from idling), in nanoseconds.
    #[must_use]
    pub fn used(&self) -> u64 {
        self.used.get()
    }
}

/// A viewer's place at a gate.
#[derive(Clone, Copy, Debug)]
pub struct Seat<'a> {
    pub gate: &'a RenderGate,
    pub account: &'a Account,
}

impl<'a> Seat<'a> {
    /// Waits for a slot; see [`RenderGate::enter`].
    #[must_use]
    pub fn enter(self) -> Turn<'a> {
        self.gate.enter(self.account)
    }
}

/// A frame's slot; dropping it charges the time held to the account and frees the
/// slot for the next waiting frame.
#[derive(Debug)]
pub struct Turn<'a> {
    gate: &'a RenderGate,
    account: &'a Account,
    since: Instant,
}

impl RenderGate {
    /// A gate with `slots` frames at once (at least one).
    #[must_use]
    pub fn new(slots: usize) -> Self {
        Self {
            state: Mutex::new(State {
                slots: slots.max(1),
                busy: 0,
                waiting: Vec::new(),
                arrivals: 0,
                floor: 0,
            }),
            turn: Condvar::new(),
        }
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Waits until a slot is free and no waiting frame's account has used less.
    pub fn enter<'a>(&'a self, account: &'a Account) -> Turn<'a> {
        let mut s = self.lock();
        let used = account.used.get().max(s.floor);
        account.used.set(used);
        let me = (used, s.arrivals);
        s.arrivals += 1;
        s.waiting.push(me);
        loop {
            let first = s.waiting.iter().min().copied();
            if s.busy < s.slots && first == Some(me) {
                break;
            }
            s = self.turn.wait(s).unwrap_or_else(|e| e.into_inner());
        }
        s.waiting.retain(|w| *w != me);
        s.busy += 1;
        s.floor = s.floor.max(used);
        drop(s);
        // Another slot may be free for the next in line.
        self.turn.notify_all();
        Turn {
            gate: self,
            account,
            since: Instant::now(),
        }
    }
}

impl Drop for Turn<'_> {
    fn drop(&mut self) {
        let held = u64::try_from(self.since.elapsed().as_nanos()).unwrap_or(u64::MAX);
        let mut s = self.gate.lock();
        self.account
            .used
            .set(self.account.used.get().saturating_add(held));
        s.busy -= 1;
        drop(s);
        self.gate.turn.notify_all();
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::time::Duration;

    use super::*;

    /// No more than `n` turns at once, however many threads ask.
    #[test]
    fn the_gate_admits_n_at_once() {
        let gate = Arc::new(RenderGate::new(2));
        let (inside, most) = (Arc::new(AtomicUsize::new(0)), Arc::new(AtomicUsize::new(0)));
        let threads: Vec<_> = (0..6)
            .map(|_| {
                let (gate, inside, most) = (gate.clone(), inside.clone(), most.clone());
                std::thread::spawn(move || {
                    let account = Account::default();
                    for _ in 0..50 {
                        let _t = gate.enter(&account);
                        let k = inside.fetch_add(1, Ordering::SeqCst) + 1;
                        most.fetch_max(k, Ordering::SeqCst);
                        std::thread::yield_now();
                        inside.fetch_sub(1, Ordering::SeqCst);
                    }
                })
            })
            .collect();
        for t in threads {
            t.join().expect("no panic");
        }
        assert_eq!(most.load(Ordering::SeqCst), 2);
    }

    /// With one slot, a viewer whose frames take three times as long gets about a
    /// third of the frames and the same time (first come, first served would give
    /// both the same frames, so the slow one three quarters of the time).
    #[test]
    fn viewers_share_the_slots_by_time_not_by_frames() {
        let gate = Arc::new(RenderGate::new(1));
        let start = Instant::now();
        let run = |cost: Duration| {
            let gate = gate.clone();
            std::thread::spawn(move || {
                let account = Account::default();
                let mut frames = 0u32;
                while start.elapsed() < Duration::from_millis(600) {
                    let _t = gate.enter(&account);
                    // Busy, as a frame is (a sleep may take far longer than asked).
                    let t = Instant::now();
                    while t.elapsed() < cost {
                        std::hint::spin_loop();
                    }
                    frames += 1;
                }
                (frames, account.used())
            })
        };
        let (slow, fast) = (run(Duration::from_millis(9)), run(Duration::from_millis(3)));
        let (slow, fast) = (slow.join().expect("slow"), fast.join().expect("fast"));
        let time = slow.1 as f64 / fast.1 as f64;
        let frames = f64::from(fast.0) / f64::from(slow.0);
        assert!((0.6..1.6).contains(&time), "time shares {slow:?} {fast:?}");
        // First come, first served gives a ratio near 1. Preemption on a busy machine
        // stretches the short frames most, so the ratio falls below the ideal 3.
        assert!(frames > 1.3, "frames {slow:?} {fast:?}");
    }

    /// An account that sat out starts level with the others rather than taking every
    /// slot until it has caught up.
    #[test]
    fn a_returning_viewer_cannot_save_up_a_burst() {
        let gate = RenderGate::new(1);
        let busy = Account::default();
        for _ in 0..3 {
            let _t = gate.enter(&busy);
            std::thread::sleep(Duration::from_millis(5));
        }
        let back = Account::default();
        drop(gate.enter(&back));
        assert!(back.used() >= busy.used() - 6_000_000, "{back:?} {busy:?}");
    }
}
