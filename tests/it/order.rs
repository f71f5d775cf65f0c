//! The editor's system order: built headless with the plugins of the window app (all but
//! the egui panels, which only push edits from their own schedule), Bevy's ambiguity
//! detection lists every pair of our systems in `Update` and `PostUpdate` that touch the
//! same data mutably with no order between them. There must be none but the few allowed
//! below, each with its reason.

use bevy::ecs::schedule::{LogLevel, ScheduleBuildSettings, ScheduleLabel};
use bevy::prelude::*;
use marionette::editor::InteractionPlugin;
use marionette::editor::present::view::ViewPlugin;
use marionette::scene::{RigCorePlugin, SkinningPlugin};

/// Pairs of our systems allowed to run in either order, with why that is harmless.
const ALLOWED: &[(&str, &str, &str)] = &[];

/// Our systems that conflict in `label`, as (system, system, what they both touch).
fn our_conflicts(app: &mut App, label: impl ScheduleLabel + Clone) -> Vec<(String, String, String)> {
    let mut found = Vec::new();
    let world = app.world_mut();
    let mut schedule = world.resource_mut::<Schedules>().remove(label.clone()).expect("the schedule exists");
    {
        schedule.set_build_settings(ScheduleBuildSettings {
            ambiguity_detection: LogLevel::Warn,
            ..ScheduleBuildSettings::default()
        });
        schedule.initialize(world).expect("the schedule builds");
        // The systems have moved into the executable schedule: their names by key.
        let names: std::collections::HashMap<_, String> =
            schedule.systems().expect("initialised").map(|(key, system)| (key, system.name().to_string())).collect();
        for (a, b, on) in schedule.graph().conflicting_systems().iter() {
            let (a, b) = (names[a].clone(), names[b].clone());
            if a.starts_with("marionette::") && b.starts_with("marionette::") {
                let on: Vec<String> = on
                    .iter()
                    .map(|id| world.components().get_name(*id).map_or("?".into(), |n| n.to_string()))
                    .collect();
                found.push((a, b, on.join(", ")));
            }
        }
    }
    world.resource_mut::<Schedules>().insert(schedule);
    found
}

#[test]
fn our_systems_that_write_the_same_data_are_ordered() {
    let mut app = App::new();
    app.add_plugins(marionette::editor::windowless_plugins()).add_plugins((
        RigCorePlugin,
        SkinningPlugin,
        ViewPlugin,
        InteractionPlugin,
    ));
    app.finish();
    app.cleanup();
    let mut conflicts = our_conflicts(&mut app, Update);
    conflicts.extend(our_conflicts(&mut app, PostUpdate));
    let unexplained: Vec<String> = conflicts
        .iter()
        .filter(|(a, b, _)| {
            !ALLOWED.iter().any(|(x, y, _)| (a.ends_with(x) && b.ends_with(y)) || (a.ends_with(y) && b.ends_with(x)))
        })
        .map(|(a, b, on)| format!("{a} / {b} on [{on}]"))
        .collect();
    assert!(
        unexplained.is_empty(),
        "{} unordered pairs of our systems:\n{}",
        unexplained.len(),
        unexplained.join("\n")
    );
}
