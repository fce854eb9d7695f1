#![allow(unsafe_code)] // a counting global allocator is unsafe by nature; test-only
//! Once bound, the player's systems allocate nothing per frame: playing,
//! and cross-fading once the incoming clip has started. Counted by a
//! global allocator on the app's thread only, between two systems that
//! run right before and right after `TcbSystems::Animate`.

mod common;

use bevy::app::PostUpdate;
use bevy::ecs::schedule::IntoScheduleConfigs;
use bevy::transform::TransformSystems;
use bevy::transform::components::Transform;
use common::{app, data_dir, load};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::Path;
use tcb_bevy::{TcbPlayer, TcbSystems, spawn_skeleton};

struct Counting;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn count() {
    if COUNTING.with(Cell::get) {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn start_counting() {
    COUNTING.with(|c| c.set(true));
}

fn stop_counting() {
    COUNTING.with(|c| c.set(false));
}

fn counted() -> usize {
    ALLOCATIONS.with(|c| c.replace(0))
}

#[test]
fn playing_and_cross_fading_allocate_nothing_per_frame() {
    let dir = data_dir();
    let mut app = app(Path::new(&dir));
    app.add_systems(
        PostUpdate,
        (
            start_counting.before(TcbSystems::Animate),
            stop_counting
                .after(TcbSystems::Animate)
                .before(TransformSystems::Propagate),
        ),
    );
    let clip = load(&mut app, "cmu-01_01.bvh").unwrap();
    let skeleton = app
        .world()
        .resource::<bevy::asset::Assets<tcb_bevy::TcbClip>>()
        .get(&clip)
        .unwrap()
        .skeleton()
        .unwrap()
        .clone();
    let world = app.world_mut();
    let root = world
        .spawn((Transform::IDENTITY, TcbPlayer::new(clip.clone())))
        .id();
    spawn_skeleton(&mut world.commands(), &skeleton, root);
    world.flush();
    app.update(); // binds: allocates, once (and shows that the count counts)
    assert!(counted() > 0);
    for _ in 0..30 {
        app.update();
    }
    assert_eq!(counted(), 0, "playing");
    app.world_mut()
        .get_mut::<TcbPlayer>(root)
        .unwrap()
        .cross_fade(clip, 0.25);
    app.update(); // starts the incoming clip: its instance is allocated, once
    assert!(counted() > 0);
    for _ in 0..10 {
        app.update();
    }
    assert!(app.world().get::<TcbPlayer>(root).unwrap().weight() < 1.0);
    assert_eq!(counted(), 0, "cross-fading");
}
