//! A generator step allocates nothing: counted by a global allocator in this test binary (one
//! test, so no other thread allocates while it counts).

use inbetween_camera::infer::{key_vector, FastModel, Rollout};
use inbetween_camera::model::{ModelConfig, MAP_FRAMES};
use inbetween_nn::runtime::{Lstm, LstmScratch, LstmState};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations_in(f: impl FnOnce()) -> usize {
    let before = ALLOCATIONS.load(Ordering::SeqCst);
    f();
    ALLOCATIONS.load(Ordering::SeqCst) - before
}

#[test]
fn runtime_layers_and_rollout_steps_do_not_allocate() {
    let device = inbetween_nn::backend::cpu();
    let cfg = ModelConfig { hidden: 16, tta_dim: 8, ..ModelConfig::default() };
    let model = FastModel::from_burn(&inbetween_nn::backend::seeded_module(&device, 3, |d| cfg.init(d)), cfg);

    // nn::runtime's LSTM with its scratch buffers.
    let lstm: &Lstm = &model.gen_lstm;
    let mut state = LstmState::zeros(4, 16);
    let mut scratch = LstmScratch::for_rows(lstm, 4);
    let x = vec![0.3f32; 4 * 16];
    lstm.step(&x, &mut state, 4, &mut scratch);
    let n = allocations_in(|| {
        for _ in 0..10 {
            lstm.step(&x, &mut state, 4, &mut scratch);
        }
    });
    assert_eq!(n, 0, "Lstm::step allocated {n} times");

    // The generator along a trajectory, including H restarts at keys.
    let style = [0.1f32, -0.2, 0.0, 0.3];
    let mut rollout = Rollout::mapped(&model, &style, &[[0.0, 0.0, 0.1, 0.0, 1.5, 0.2]; MAP_FRAMES]);
    let key = key_vector(&[0.2, 0.1, 0.3, 0.0, 1.8, 0.1], &[0.5; 8]);
    let mut last = [0.0f32; 6];
    let n = allocations_in(|| {
        for t in 0..20 {
            last = rollout.step(&[0.4; 8], &key, 100 - 5 * t);
            if t % 7 == 6 {
                rollout.restart_from_arrival();
            }
        }
    });
    assert_eq!(n, 0, "Rollout::step allocated {n} times");
    assert!(last.iter().all(|v| v.is_finite()) && last != [0.0; 6], "the steps ran");
    // Counting works: a Vec allocates.
    assert!(allocations_in(|| drop(std::hint::black_box(vec![1u8; 64]))) >= 1);
}
