//! Unit tests of the edit scripts and the diff drawing's options.

use super::script::key_order;
use super::*;
use btfsm_format::toml::parse_str;
use std::path::Path;

fn pair<'a>(a: &'a Policy, b: &'a Policy) -> Pair<'a> {
    let side = |policy| Side {
        file: "test.toml",
        policy,
    };
    Pair::new(side(a), side(b))
}

fn policy(src: &str) -> Policy {
    parse_str("test.toml", src, Path::new(""), &Default::default())
        .expect("valid")
        .policy
}

const A: &str = r#"
kind = "fsm"
initial = "Go"
outcomes = ["SUCCESS"]
[states.Go]
skill = "Move-To"
args = { target = "cube2" }
on = { SUCCESS = "Pick", FAILURE = "Go", RUNNING = "Go" }
[states.Pick]
skill = "Pick"
args = { object = "cube2" }
on = { SUCCESS = "SUCCESS", FAILURE = "Go", RUNNING = "Pick" }
"#;

/// A with `Safe-Move-To` as the alternative to `Go` (Fig. 8b's edit).
fn b() -> String {
    A.replace(
        "on = { SUCCESS = \"Pick\", FAILURE = \"Go\", RUNNING = \"Go\" }",
        "on = { SUCCESS = \"Pick\", FAILURE = \"Safe\", RUNNING = \"Go\" }\n\
         [states.Safe]\n\
         skill = \"Safe-Move-To\"\n\
         args = { target = \"cube2\" }\n\
         on = { SUCCESS = \"Pick\", FAILURE = \"Go\", RUNNING = \"Safe\" }",
    )
}

#[test]
fn named_script_tells_arcs_apart_by_label() {
    let (pa, pb) = (policy(A), policy(&b()));
    let pair = pair(&pa, &pb);
    let m = pair.run(GedMode::Named, &GedOptions::default());
    let s = &m.edit_script;
    assert_eq!(m.ged, s.cost());
    // Go's FAILURE self-loop goes, Safe and its three arcs and Go -> Safe come.
    let arc = |f: &str, t: &str, l: &str| ArcRef {
        from: f.into(),
        to: t.into(),
        label: l.into(),
        count: 1,
        label_in_a: None,
    };
    assert_eq!(s.arcs_removed, vec![arc("Go", "Go", "FAILURE")]);
    assert_eq!(
        s.arcs_added,
        vec![
            arc("Go", "Safe", "FAILURE"),
            arc("Safe", "Go", "FAILURE"),
            arc("Safe", "Pick", "SUCCESS"),
            arc("Safe", "Safe", "RUNNING"),
        ]
    );
    assert_eq!(s.vertices_added.len(), 1);
    assert_eq!(s.vertices_added[0].key, "Safe");
    assert_eq!(m.ged, 6);
    // The structural optimum is no larger and its script costs what it says.
    let st = pair.run(GedMode::Structural, &GedOptions::default());
    assert!(st.exact && st.ged <= m.ged);
    assert_eq!(st.edit_script.cost(), st.ged);
}

/// A random FSM: `n` states, each with three outcome arcs to random
/// states (parallel arcs and self-loops with different labels).
fn random_fsm(n: u64, seed: u64) -> String {
    let mut x = seed;
    let mut next = move |m: u64| {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x % m
    };
    let mut s = String::from("kind = \"fsm\"\ninitial = \"s0\"\noutcomes = [\"SUCCESS\"]\n");
    for i in 0..n {
        let to = |t: u64| {
            if t == n {
                "SUCCESS".to_string()
            } else {
                format!("s{t}")
            }
        };
        s.push_str(&format!(
            "[states.s{i}]\nskill = \"Dock\"\non = {{ SUCCESS = \"{}\", FAILURE = \"{}\", RUNNING = \"{}\" }}\n",
            to(next(n + 1)),
            to(next(n + 1)),
            to(next(n + 1)),
        ));
    }
    s
}

/// The script of any partial mapping costs what `mapping_cost` says,
/// accounts for every arc of both graphs once, and comes out in the
/// order the old string sorts gave (vertices by key, arcs by `ArcRef`).
#[test]
fn scripts_of_random_mappings_are_complete_and_sorted() {
    use btfsm_metrics::ged::{Shape, mapping_cost};
    let (pa, pb) = (policy(&random_fsm(12, 3)), policy(&random_fsm(10, 8)));
    let pair = pair(&pa, &pb);
    let (sa, sb) = (Shape::from(&pair.ga), Shape::from(&pair.gb));
    let (na, nb) = (sa.n(), sb.n());
    let mut x = 99u64;
    for round in 0..200 {
        let map: Vec<Option<usize>> = (0..na)
            .map(|_| {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let r = (x >> 33) as usize;
                (!r.is_multiple_of(4)).then_some(r % (nb + 1))
            })
            .collect();
        let s = pair.script(&map);
        assert_eq!(s.cost(), mapping_cost(&sa, &sb, &map), "round {round}");
        let count = |l: &[ArcRef]| l.iter().map(|a| u64::from(a.count)).sum::<u64>();
        assert_eq!(count(&s.arcs_kept) + count(&s.arcs_removed), sa.arc_count());
        assert_eq!(count(&s.arcs_kept) + count(&s.arcs_added), sb.arc_count());
        assert_eq!(s.vertices_kept.len() + s.vertices_removed.len(), na);
        assert_eq!(s.vertices_kept.len() + s.vertices_added.len(), nb);
        for l in [&s.arcs_kept, &s.arcs_removed, &s.arcs_added] {
            assert!(l.windows(2).all(|w| w[0] < w[1]), "round {round}: {l:?}");
        }
        let keys = |l: &[VertexRef]| l.windows(2).all(|w| w[0].key < w[1].key);
        assert!(keys(&s.vertices_added) && keys(&s.vertices_removed));
        assert!(
            s.vertices_kept
                .windows(2)
                .all(|w| (&w[0].a, &w[0].b) < (&w[1].a, &w[1].b))
        );
    }
}

#[test]
fn key_order_is_the_string_order() {
    let keys = [
        "n10",
        "n9",
        "",
        "a",
        "ab",
        "ab\0",
        "abcdefgh",
        "abcdefghi",
        "abcdefgh",
        "é",
        "Z",
        "abcdefgha",
        "n1",
    ];
    let got: Vec<&str> = key_order(keys.len(), |i| keys[i as usize])
        .into_iter()
        .map(|i| keys[i as usize])
        .collect();
    let mut want = keys.to_vec();
    want.sort();
    assert_eq!(got, want);
}

#[test]
fn relabelled_parallel_arc_is_kept_and_shown() {
    let b = A.replace(
        "FAILURE = \"Go\", RUNNING = \"Go\"",
        "FAILURE = \"Go\", RUNNING = \"Pick\"",
    );
    let (pa, pb) = (policy(A), policy(&b));
    let pair = pair(&pa, &pb);
    let m = pair.run(GedMode::Named, &GedOptions::default());
    // Go -> Go loses its RUNNING arc; Go -> Pick gains one (now 2 arcs).
    assert_eq!(m.ged, 2);
    assert_eq!(m.edit_script.arcs_removed.len(), 1);
    assert_eq!(m.edit_script.arcs_removed[0].label, "RUNNING");
    assert_eq!(m.edit_script.arcs_added[0].label, "RUNNING");
    assert!(
        m.edit_script
            .arcs_kept
            .iter()
            .all(|a| a.label_in_a.is_none())
    );
}

#[test]
fn dot_options_never_reuse_a_key_of_b_for_a_ghost() {
    // Structurally, b's `Safe` may take a's place under another key; a
    // removed vertex whose key b also uses must be drawn apart.
    let (pa, pb) = (policy(&b()), policy(A));
    let pair = pair(&pa, &pb);
    for mode in [GedMode::Structural, GedMode::Named] {
        let m = pair.run(mode, &GedOptions::default());
        let o = pair.dot_options(&m.edit_script);
        assert_eq!(o.ghost_vertices.len(), 1);
        let b_keys: Vec<_> = pair.gb.g.node_weights().map(|v| v.key.clone()).collect();
        assert!(!b_keys.contains(&o.ghost_vertices[0].0));
        let ghost_arcs: u64 = o.ghost_arcs.len() as u64;
        let removed: u64 = m
            .edit_script
            .arcs_removed
            .iter()
            .map(|a| u64::from(a.count))
            .sum();
        assert_eq!(ghost_arcs, removed);
    }
}
