//! The step loop allocates nothing: the number of heap allocations of a run does not depend on
//! the number of steps (connections, recording into a writer or into memory, multi-rate, both
//! algorithms).
mod common;
use common::*;
use shipsim::run::{load_fmus, run, run_into, MemoryRecorder, Output, RunOptions};
use shipsim::system::System;
use std::alloc::{GlobalAlloc, Layout, System as SysAlloc};
use std::sync::atomic::{AtomicUsize, Ordering};

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
fn allocations_do_not_grow_with_steps() {
    let d = tempfile::tempdir().unwrap();
    test_fmu(d.path());
    for algo in ["jacobi", "gauss-seidel"] {
        let p = write_system(
            d.path(),
            "a.toml",
            &format!(
                r#"
connections = ["a.y -> b.u", {{ from = "b.y2", to = "c.u", gain = 0.5 }}, "c.n_out -> a.n_in", "a.enabled_out -> c.enabled"]
[simulation]
stop_time = 1.0
step_size = 0.001
algorithm = "{algo}"
[[instances]]
name = "a"
fmu = "testfmu.fmu"
parameters = {{ u = 1.0 }}
[[instances]]
name = "b"
fmu = "testfmu.fmu"
step_multiple = 10
[[instances]]
name = "c"
fmu = "testfmu.fmu"
[[events]]
time = 0.5
set = "a.u"
value = 2.0
"#
            ),
        );
        let mut sys = System::load(&p).unwrap();
        let fmus = load_fmus(&sys).unwrap();
        let mds: Vec<_> = fmus.iter().map(|f| &f.model_description).collect();
        let (mut counts, mut memory_counts) = (Vec::new(), Vec::new());
        for stop in [1.0, 100.0] {
            sys.stop_time = Some(stop);
            let plan = sys.validate(&mds).unwrap();
            let before = ALLOCS.load(Ordering::SeqCst);
            let s = run(
                &plan,
                &fmus,
                Output::Writer(Box::new(std::io::sink())),
                &RunOptions::default(),
            )
            .unwrap();
            counts.push(ALLOCS.load(Ordering::SeqCst) - before);
            assert_eq!(s.macro_steps, (stop * 1000.0) as u64);
            let mut memory = MemoryRecorder::new();
            let before = ALLOCS.load(Ordering::SeqCst);
            let s = run_into(&plan, &fmus, Some(&mut memory), &RunOptions::default()).unwrap();
            memory_counts.push(ALLOCS.load(Ordering::SeqCst) - before);
            assert_eq!(memory.time.len() as u64, s.rows);
            assert_eq!(s.rows, s.macro_steps + 1);
        }
        assert_eq!(
            counts[0], counts[1],
            "{algo}: allocations for 1e3 vs 1e5 steps: {counts:?}"
        );
        assert_eq!(
            memory_counts[0], memory_counts[1],
            "{algo}, in memory: allocations for 1e3 vs 1e5 steps: {memory_counts:?}"
        );
    }
}
