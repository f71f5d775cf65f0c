//! One compute worker a core, so that the skin phase's parallel work never lands two
//! workers on one core while another idles (left to the scheduler they can wake on the same
//! core). Only the compute workers are pinned: the main thread and the threads it starts
//! (the renderer's, the IO and async pools) keep every core.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use bevy::prelude::*;

/// A callback for the compute pool's threads as they start: the k-th pins itself to the
/// k-th core this process may run on (wrapping round). None where pinning is not
/// available (not Linux) or the process may run on one core only.
pub fn pin_each_worker_to_a_core() -> Option<Arc<dyn Fn() + Send + Sync + 'static>> {
    let cores = allowed_cores();
    if cores.len() < 2 {
        return None;
    }
    let next = AtomicUsize::new(0);
    Some(Arc::new(move || {
        let k = next.fetch_add(1, Ordering::Relaxed);
        pin_this_thread_to(&[cores[k % cores.len()]]);
    }))
}

/// The cores this process may run on, ascending (its affinity mask, which `taskset` and
/// container limits narrow).
#[cfg(target_os = "linux")]
pub fn allowed_cores() -> Vec<usize> {
    // SAFETY: `set` is a plain bit set that `sched_getaffinity` fills (pid 0: this thread,
    // whose mask is the process's until a thread is pinned).
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        if libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut set) != 0 {
            return Vec::new();
        }
        (0..libc::CPU_SETSIZE as usize).filter(|&c| libc::CPU_ISSET(c, &set)).collect()
    }
}

#[cfg(not(target_os = "linux"))]
pub fn allowed_cores() -> Vec<usize> {
    Vec::new()
}

/// Lets the calling thread run on `cores` only (a hint: where the system refuses, it runs
/// anywhere).
#[cfg(target_os = "linux")]
fn pin_this_thread_to(cores: &[usize]) {
    // SAFETY: as in `allowed_cores`; the set holds cores below `CPU_SETSIZE` only.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        cores.iter().filter(|&&c| c < libc::CPU_SETSIZE as usize).for_each(|&c| libc::CPU_SET(c, &mut set));
        libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set);
    }
}

#[cfg(not(target_os = "linux"))]
fn pin_this_thread_to(_cores: &[usize]) {}

/// Bevy's task pools with every core for compute (systems and the parallel skinning),
/// each compute worker on a core of its own ([`pin_each_worker_to_a_core`]): one thread each for IO and async
/// tasks on top, instead of taking them from the cores (on 2 cores Bevy's default leaves
/// compute a single thread).
pub fn task_pools() -> bevy::app::TaskPoolPlugin {
    let one = |policy: bevy::app::TaskPoolThreadAssignmentPolicy| bevy::app::TaskPoolThreadAssignmentPolicy {
        min_threads: 1,
        max_threads: 1,
        ..policy
    };
    let defaults = bevy::app::TaskPoolOptions::default();
    let core_count = bevy::tasks::available_parallelism();
    bevy::app::TaskPoolPlugin {
        task_pool_options: bevy::app::TaskPoolOptions {
            min_total_threads: core_count + 2,
            max_total_threads: core_count + 2,
            io: one(defaults.io),
            async_compute: one(defaults.async_compute),
            compute: bevy::app::TaskPoolThreadAssignmentPolicy {
                on_thread_spawn: pin_each_worker_to_a_core(),
                ..defaults.compute
            },
        },
    }
}

/// Bevy's default plugins without a window (the headless renderer, the bench, tests):
/// rendering into images, with [`task_pools`].
pub fn windowless_plugins() -> bevy::app::PluginGroupBuilder {
    DefaultPlugins
        .set(task_pools())
        .set(WindowPlugin {
            primary_window: None,
            exit_condition: bevy::window::ExitCondition::DontExit,
            close_when_requested: false,
            ..default()
        })
        .disable::<bevy::winit::WinitPlugin>()
}
