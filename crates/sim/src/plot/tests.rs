//! Tests of the simulator plot: the picture's parts are there, it is
//! well-formed XML, labels avoid markers, identical paths are named.

use super::*;
use crate::{run::run_scenario, scenario};
use btfsm_core::diagnostic::SourceFile;
use btfsm_format::Limits;
use std::path::Path;

fn scenario_of(text: &str) -> Scenario {
    let f = SourceFile::new("t.toml", text);
    scenario::parse(
        &f,
        Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../policies/scenarios"
        )),
        &Limits::default(),
    )
    .unwrap()
}

fn plot(text: &str) -> (Scenario, Vec<Run>, String) {
    let s = scenario_of(text);
    let runs = run_scenario(&s, false);
    let svg = svg(&s, &runs);
    (s, runs, svg)
}

const TWO_POLICIES: &str = r#"
[world]
objects = { cube2 = { at = "east-table" } }
[[policies]]
file = "../paper/fig01-bt.toml"
[[policies]]
file = "../paper/fig04-fsm.toml"
"#;

#[test]
fn plot_has_room_obstacles_trajectories_and_markers() {
    let (_, _, svg) = plot(
        r#"
[world]
objects = { cube2 = { at = "east-table" } }
[[policies]]
file = "../paper/fig01-bt.toml"
[[disturbances]]
at = 1.0
block = { name = "crate", rect = [-1.0, -2.9, -0.9, -2.5] }
"#,
    );
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.contains(">central table<") && svg.contains("crate (blocked later)"));
    assert!(svg.contains(r#"<path d="M"#), "a trajectory");
    assert!(
        svg.contains("Pick(object=cube2) -&gt; success"),
        "a pick marker"
    );
    assert_eq!(svg.matches("<svg").count(), 1);
    roxmltree::Document::parse(&svg).expect("well-formed XML");
}

#[test]
fn plot_has_axes_in_metres_and_a_scale_bar() {
    let (s, _, svg) = plot(TWO_POLICIES);
    let r = &s.world.layout.room;
    // The paper room spans -3..3 m: ticks every metre on both axes.
    assert_eq!((r.x0, r.x1, r.y0, r.y1), (-3.0, 3.0, -3.0, 3.0));
    for v in ["-3", "-2", "-1", "0", "1", "2", "3"] {
        let tick = format!(">{v}</text>");
        assert_eq!(svg.matches(&tick).count(), 2, "x and y ticks of {v}");
    }
    assert!(svg.contains(">x (m)<") && svg.contains(">y (m)<"));
    assert!(svg.contains(">1 m<"), "scale bar");
    // The scale bar is SCALE pixels long: one metre of the room.
    assert!(svg.contains(&format!("l{SCALE},0")));
}

#[test]
fn tick_steps_are_round_and_few() {
    assert_eq!(tick_step(6.0), 1.0);
    assert_eq!(tick_step(1.0), 0.2);
    assert_eq!(tick_step(30.0), 5.0);
    assert_eq!(metres(-0.0), "0");
    assert_eq!(metres(2.5), "2.5");
}

#[test]
fn placed_objects_are_drawn_where_they_lie() {
    let (s, runs, svg) = plot(TWO_POLICIES);
    // Both policies deliver cube2: it ends at the delivery station.
    let delivered = &runs[0].final_world.objects["cube2"];
    assert_eq!(delivered.at.as_deref(), Some("delivery"));
    let f = Frame {
        x0: s.world.layout.room.x0,
        y1: s.world.layout.room.y1,
    };
    let corner = format!(
        r##"<rect x="{:.1}" y="{:.1}" width="8" height="8" fill="#f2c200""##,
        f.px((delivered.x * 100.0).round() / 100.0) - 4.0,
        f.py((delivered.y * 100.0).round() / 100.0) - 4.0
    );
    assert!(svg.contains(&corner), "an end square at the delivery pose");
    assert!(svg.contains(&format!(
        "cube2 left here by {}, {}",
        runs[0].policy, runs[1].policy
    )));
    assert!(svg.contains("cube2 at the start"));
}

#[test]
fn identical_paths_are_named_in_the_legend() {
    let (_, runs, svg) = plot(TWO_POLICIES);
    assert_eq!(
        same_paths(&runs),
        vec![vec![0, 1]],
        "Fig. 1 and Fig. 4 drive alike"
    );
    assert!(svg.contains(&format!(
        "Same path: {} = {}.",
        runs[0].policy, runs[1].policy
    )));
    assert!(svg.contains("px apart"));
}

#[test]
fn different_paths_are_not_called_the_same() {
    let (_, runs, svg) = plot(
        r#"
[world]
objects = { cube2 = { at = "east-table" } }
[[policies]]
file = "../paper/fig01-bt.toml"
[[policies]]
file = "../paper/fig02-fsm.toml"
after_failure = "stop"
[[disturbances]]
at = 4.0
move = "cube2"
to = [1.7, -0.8]
"#,
    );
    assert_ne!(runs[0].trajectory, runs[1].trajectory);
    assert!(same_paths(&runs).is_empty());
    assert!(!svg.contains("Same path"));
}

#[test]
fn a_hostile_name_stays_text() {
    let (_, _, svg) = plot(
        r#"
[world]
objects = { cube2 = { at = "east-table" }, "</text><script>x</script>\u0001" = { at = "west-table" } }
[[policies]]
file = "../paper/fig01-bt.toml"
"#,
    );
    assert!(!svg.contains("<script>"));
    assert!(
        svg.contains("&lt;/text&gt;&lt;script&gt;x&lt;/script&gt;\\u{1}"),
        "escaped, control shown"
    );
    roxmltree::Document::parse(&svg).expect("well-formed XML");
}

/// Arrowheads every metre point along the direction of travel: out and
/// back along one line gives arrows both ways; their number is bounded
/// whatever the length.
#[test]
fn arrows_show_out_and_back_motion() {
    let tip_dirs = |d: &str| -> Vec<f64> {
        // Each head: `M tip L base1 L base2 Z`; its direction is tip − the
        // bases' midpoint, in x.
        d.split('Z')
            .filter(|h| !h.trim().is_empty())
            .map(|h| {
                let n: Vec<f64> = h
                    .split(['M', 'L', ',', ' '])
                    .filter_map(|t| t.parse().ok())
                    .collect();
                n[0] - (n[2] + n[4]) / 2.0
            })
            .collect()
    };
    let out_and_back = [(0.0, 0.0), (500.0, 0.0), (0.0, 0.0)];
    let dirs = tip_dirs(&marks::arrows(&out_and_back));
    assert_eq!(dirs.len(), 10, "{dirs:?}");
    assert!(dirs[..5].iter().all(|&x| x > 0.0) && dirs[5..].iter().all(|&x| x < 0.0));
    let far = [(0.0, 0.0), (1e7, 0.0)];
    assert!(tip_dirs(&marks::arrows(&far)).len() <= marks::MAX_ARROWS + 1);
    assert!(marks::arrows(&[(1.0, 1.0)]).is_empty());
    let (_, _, svg) = plot(TWO_POLICIES);
    assert_eq!(svg.matches(r#"class="arrows""#).count(), 2);
}
