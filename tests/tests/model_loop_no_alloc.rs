//! The macro steps of the pure-Rust RRS model loop allocate nothing (counted by a global
//! allocator over every step of a run, RRS on and off, and over recording into a CSV writer).

use models::controllers::rrs::RollMode;
use std::alloc::{GlobalAlloc, Layout, System as SysAlloc};
use std::sync::atomic::{AtomicUsize, Ordering};
use system_tests::model_loop::rrs::{RrsLoop, RrsParams, COLUMNS};
use system_tests::model_loop::CsvWriter;

struct Counting;
static ALLOCS: AtomicUsize = AtomicUsize::new(0);
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        SysAlloc.alloc(l)
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        SysAlloc.dealloc(p, l)
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
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
        let before = ALLOCS.load(Ordering::SeqCst);
        while system.step_index() < system.n_steps() {
            system.macro_step();
            csv.row(system.time(), &system.values().recorded());
        }
        let allocations = ALLOCS.load(Ordering::SeqCst) - before;
        assert_eq!(system.step_index(), 2001);
        assert_eq!(allocations, 0, "{roll_mode:?}");
        csv.finish().unwrap();
    }
}
