//! The macro steps of the pure-Rust RRS model loop allocate nothing (counted by a global
//! allocator over every step of a run, RRS on and off, and over recording into a CSV writer).

use models::controllers::rrs::RollMode;
use std::alloc::{GlobalAlloc, Layout, System as SysAlloc};
use std::cell::Cell;
use system_tests::model_loop::rrs::{RrsLoop, RrsParams, COLUMNS};
use system_tests::model_loop::CsvWriter;

/// Counts the allocations of each thread: the test harness's own threads may allocate while
/// the loop runs (a process-wide count failed once in CI, with 4 allocations not the loop's).
struct Counting;
thread_local! {
    static ALLOCS: Cell<usize> = const { Cell::new(0) };
}
fn allocs() -> usize {
    ALLOCS.with(|c| c.get())
}
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        SysAlloc.alloc(l)
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        SysAlloc.dealloc(p, l)
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        SysAlloc.realloc(p, l, n)
    }
}
#[global_allocator]
static A: Counting = Counting;

#[test]
fn macro_steps_allocate_nothing() {
    for roll_mode in [RollMode::On, RollMode::Off] {
        let params = RrsParams {
            roll_mode,
            ..RrsParams::default()
        };
        // an odd number of steps: the last step of the slow instances is shortened
        let mut system = RrsLoop::new(&params, 100.05).unwrap();
        let mut csv = CsvWriter::new(std::io::sink(), &COLUMNS).unwrap();
        let before = allocs();
        while system.step_index() < system.n_steps() {
            system.macro_step();
            csv.row(system.time(), &system.values().recorded());
        }
        let allocations = allocs() - before;
        assert_eq!(system.step_index(), 2001);
        assert_eq!(allocations, 0, "{roll_mode:?}");
        csv.finish().unwrap();
    }
}
