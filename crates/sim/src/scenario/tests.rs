//! The scenario reader on valid, invalid and hostile scenarios.

use super::*;
use btfsm_format::discover::looks_like_scenario;

fn parse_text(text: &str) -> Result<Scenario, Vec<Diagnostic>> {
    let f = SourceFile::new("s.toml", text);
    parse(
        &f,
        Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../policies/scenarios"
        )),
        &Limits::default(),
    )
}

#[test]
fn reads_a_scenario() {
    let s = parse_text(
        r#"
seed = 3
[world]
robot = "start"
objects = { cube2 = { at = "east-table" } }
[[policies]]
file = "../paper/fig01-bt.toml"
[[disturbances]]
at = 4.0
battery = 15
"#,
    )
    .unwrap();
    assert_eq!(s.seed, 3);
    assert_eq!(s.policies.len(), 1);
    assert_eq!(s.disturbances[0].effect, Effect::Battery(15.0));
}

#[test]
fn reports_unknown_names_and_poses_in_walls() {
    let e = parse_text(
        r#"
[world]
robot = [3.5, 0.0]
objects = { cube2 = { at = "east-tabel" } }
[[policies]]
file = "../paper/fig01-bt.toml"
[[disturbances]]
at = 1.0
fail = "Pik"
"#,
    )
    .unwrap_err();
    let text: Vec<String> = e.iter().map(|d| d.to_string()).collect();
    let all = text.join("");
    assert!(all.contains("inside a wall"), "{all}");
    assert!(all.contains("unknown station `east-tabel`"), "{all}");
    assert!(all.contains("did you mean `east-table`?"), "{all}");
    assert!(all.contains("unknown skill `Pik`"), "{all}");
}

#[test]
fn policy_errors_in_included_subtrees_point_at_the_include() {
    let e = parse_text(
        r#"
[world]
objects = { cube1 = { at = "east-table" } }
[[policies]]
file = "../paper/fig16a-bt.toml"
"#,
    )
    .unwrap_err();
    let first = e[0].to_string();
    assert!(
        first.contains("unknown object `cube2` in node `moma2/"),
        "{first}"
    );
    assert!(first.contains("moma2         = { subtree"), "{first}");
    assert_eq!(key_span("a = 1\n  \"b c\" = 2\n", "b c"), Some(8..13));
}

proptest::proptest! {
    #![proptest_config(proptest::test_runner::Config::with_cases(64))]
    /// Random edits of a valid scenario never panic: they parse or give
    /// positioned errors.
    #[test]
    fn mutated_scenarios_never_panic(cut in 0usize..400, junk in "[a-z\\[\\]{}=\",0-9. ]{0,12}") {
        let base = "seed = 1\n[world]\nrobot = [0.5, -1.5]\nobjects = { cube2 = { at = \"east-table\" } }\n[[policies]]\nfile = \"../paper/fig01-bt.toml\"\n[[disturbances]]\nat = 2.0\nmove = \"cube2\"\nto = [1.0, -1.0]\n";
        let cut = cut.min(base.len());
        let cut = (0..=cut).rev().find(|&i| base.is_char_boundary(i)).unwrap_or(0);
        let text = format!("{}{junk}{}", &base[..cut], &base[cut..]);
        match parse_text(&text) {
            Ok(s) => proptest::prop_assert!(!s.policies.is_empty()),
            Err(d) => proptest::prop_assert!(d.iter().any(|x| x.is_error())),
        }
    }
}

fn errors_of(text: &str) -> String {
    let e = parse_text(text).expect_err("refused");
    e.iter().map(|d| d.to_string()).collect::<Vec<_>>().join("")
}

const ONE_POLICY: &str = "[[policies]]\nfile = \"../paper/fig01-bt.toml\"\n";
const CUBE: &str = "objects = { cube2 = { at = \"east-table\" } }\n";

/// 20,000 stations were read in quadratic time (each looked up by a scan
/// of those before it); now a scenario holds at most MAX_STATIONS, and
/// the limit is checked before any entry is read.
#[test]
fn stations_are_capped_and_read_in_linear_time() {
    let stations = |n: usize| {
        let mut t = format!("[world]\n{CUBE}[world.stations]\n");
        for i in 0..n {
            t.push_str(&format!("s{i} = [-2.0, -2.2]\n"));
        }
        t + ONE_POLICY
    };
    let t = std::time::Instant::now();
    let all = errors_of(&stations(20_000));
    assert!(
        all.contains("20007 stations, more than the limit of 1024") && all.contains("s.toml:3:1"),
        "{all}"
    );
    // Up to the limit (the paper room's 7 included): accepted, and a
    // moved paper station keeps its place.
    let mut text = stations(MAX_STATIONS - 7);
    text = text.replace(
        "[world.stations]\n",
        "[world.stations]\ndelivery = [0.5, 2.0]\n",
    );
    let s = parse_text(&text).expect("at the limit");
    let l = &s.world.layout;
    assert_eq!(l.stations.len(), MAX_STATIONS);
    assert_eq!(l.stations[0], ("delivery".to_string(), (0.5, 2.0)));
    assert_eq!(l.station_index("s1016"), Some(MAX_STATIONS - 1));
    assert!(t.elapsed().as_secs() < 5, "{:?}", t.elapsed());
}

#[test]
fn policies_objects_obstacles_and_disturbances_are_capped() {
    let policies = format!("[world]\n{CUBE}{}", ONE_POLICY.repeat(MAX_POLICIES + 1));
    let all = errors_of(&policies);
    assert!(
        all.contains("65 policies, more than the limit of 64") && all.contains("s.toml:3:1"),
        "{all}"
    );
    assert_eq!(
        parse_text(&format!(
            "[world]\n{CUBE}{}",
            ONE_POLICY.repeat(MAX_POLICIES)
        ))
        .expect("64 policies")
        .policies
        .len(),
        MAX_POLICIES
    );
    let objects: String = (0..=MAX_OBJECTS)
        .map(|i| format!("o{i} = {{ at = \"east-table\" }}\n"))
        .collect();
    let all = errors_of(&format!("[world.objects]\n{objects}{ONE_POLICY}"));
    assert!(
        all.contains("1025 objects, more than the limit of 1024"),
        "{all}"
    );
    let obstacles = "{ rect = [2.5, 2.5, 2.6, 2.6] }, ".repeat(MAX_OBSTACLES + 1);
    let all = errors_of(&format!(
        "[world]\n{CUBE}obstacles = [{obstacles}]\n{ONE_POLICY}"
    ));
    assert!(
        all.contains("1025 obstacles, more than the limit of 1024"),
        "{all}"
    );
    let ds = "[[disturbances]]\nat = 1.0\nbattery = 50\n".repeat(MAX_DISTURBANCES + 1);
    let all = errors_of(&format!("[world]\n{CUBE}{ONE_POLICY}{ds}"));
    assert!(
        all.contains("1025 disturbances, more than the limit of 1024"),
        "{all}"
    );
    // `block` disturbances add obstacles: 6 of the room + 1019 blocks.
    let ds = "[[disturbances]]\nat = 1.0\nblock = { rect = [2.5, 2.5, 2.6, 2.6] }\n"
        .repeat(MAX_OBSTACLES - 5);
    let all = errors_of(&format!("[world]\n{CUBE}{ONE_POLICY}{ds}"));
    assert!(
        all.contains("1025 obstacles (`block` disturbances included)"),
        "{all}"
    );
    let terms = "{ if = \"Found\" }, ".repeat(MAX_TERMS / 2);
    let whens = format!("[[disturbances]]\nwhen = [{terms}]\nbattery = 5\n").repeat(2);
    let all = errors_of(&format!(
        "goal = [{{ if = \"Found\" }}]\n[world]\n{CUBE}{ONE_POLICY}{whens}"
    ));
    assert!(
        all.contains(
            "1025 condition terms (`goal` and every `when` together), more than the limit of 1024"
        ),
        "{all}"
    );
}

/// Refuses each scenario made of (top-level keys, lines of `[world]`,
/// tables after the policy) with a message containing the last string.
fn assert_refused(cases: &[(&str, &str, &str, &str)]) {
    for (top, world, tail, want) in cases {
        let text = format!("{top}[world]\n{CUBE}{world}{ONE_POLICY}{tail}");
        let all = match parse_text(&text) {
            Ok(_) => panic!("accepted:\n{text}"),
            Err(e) => e.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(""),
        };
        assert!(all.contains(want), "{text}\n=> {all}");
    }
}

/// NaN and infinities passed the wall and obstacle checks of `[world]`.
#[test]
fn world_numbers_are_finite() {
    assert_refused(&[
        ("", "robot = [nan, 0.0]\n", "", "s.toml:3:9"),
        (
            "",
            "robot = [0.0, inf]\n",
            "",
            "must be a position `[x, y]` in metres (finite numbers)",
        ),
        ("", "stations = { x = [nan, nan] }\n", "", "s.toml:3:18"),
        (
            "",
            "obstacles = [{ rect = [nan, 0, 1, 1] }]\n",
            "",
            "`rect` must be four finite numbers",
        ),
        (
            "",
            "obstacles = [{ rect = [0, 0, inf, 1] }]\n",
            "",
            "s.toml:3:23",
        ),
        (
            "",
            "battery = nan\n",
            "",
            "`battery` must be a finite number, found NaN",
        ),
        (
            "",
            "params = { max_speed = inf }\n",
            "",
            "`max_speed` must be a finite number, found inf",
        ),
    ]);
}

/// `max_steps = 1.5` was read as 1: the counted top-level numbers are
/// integers in range, the others finite.
#[test]
fn top_level_numbers_are_finite_integers_where_counted_and_in_range() {
    assert_refused(&[
        (
            "max_steps = 1.5\n",
            "",
            "",
            "`max_steps` must be an integer, found 1.5",
        ),
        (
            "max_steps = 10000000\n",
            "",
            "",
            "`max_steps` must be between 1 and 1000000, found 10000000",
        ),
        (
            "max_steps = nan\n",
            "",
            "",
            "`max_steps` must be an integer, found NaN",
        ),
        (
            "seed = 1e3\n",
            "",
            "",
            "`seed` must be an integer, found 1000",
        ),
        ("seed = -1\n", "", "", "`seed` must be between 0 and"),
        (
            "chatter_switches = 2.5\n",
            "",
            "",
            "`chatter_switches` must be an integer",
        ),
        (
            "max_failures = inf\n",
            "",
            "",
            "`max_failures` must be an integer, found inf",
        ),
        (
            "dt = nan\n",
            "",
            "",
            "`dt` must be a finite number, found NaN",
        ),
    ]);
    // Integers written as TOML integers still read, in any radix.
    let s = parse_text(&format!(
        "seed = 0x10\nmax_steps = 1_000\n[world]\n{CUBE}{ONE_POLICY}"
    ))
    .expect("integers");
    assert_eq!((s.seed, s.max_steps), (16, 1000));
}

/// The battery drop took any level and window: the numbers of
/// disturbances, `[monte_carlo]` and `[rates]` are finite and in range.
#[test]
fn disturbance_and_monte_carlo_numbers_are_finite_and_in_range() {
    assert_refused(&[
        (
            "",
            "",
            "[[disturbances]]\nat = inf\nbattery = 5\n",
            "`at` must be a finite number, found inf",
        ),
        (
            "",
            "",
            "[[disturbances]]\nat = 1.0\nfail = \"Pick\"\ntimes = 1.5\n",
            "`times` must be an integer, found 1.5",
        ),
        (
            "",
            "",
            "[[disturbances]]\nat = 1.0\nmove = \"cube2\"\nto = [nan, 1.0]\n",
            "s.toml:8:6",
        ),
        (
            "",
            "",
            "[monte_carlo]\nbattery_drop = { level = [nan, 19] }\n",
            "`level` must be a range `[low, high]` of finite numbers with 0 <= low <= high <= 100",
        ),
        (
            "",
            "",
            "[monte_carlo]\nbattery_drop = { level = [5, 190] }\n",
            "`level` must be a range",
        ),
        (
            "",
            "",
            "[monte_carlo]\nbattery_drop = { level = [19, 5] }\n",
            "`level` must be a range",
        ),
        (
            "",
            "",
            "[monte_carlo]\nbattery_drop = { window = [5.0, inf] }\n",
            "`window` must be a range",
        ),
        (
            "",
            "",
            "[monte_carlo]\nbattery_drop = { window = [-5.0, 1.0] }\n",
            "s.toml:6:27",
        ),
        (
            "",
            "",
            "[monte_carlo]\nbattery_drop = { probability = nan }\n",
            "`probability` must be a finite number",
        ),
        (
            "",
            "",
            "[rates]\nPick = nan\n",
            "failure rate of `Pick` must be a finite number",
        ),
    ]);
}

/// A condition's numeric arguments are finite and in range.
#[test]
fn condition_arguments_are_finite_and_in_range() {
    assert_refused(&[
        (
            "goal = [{ if = \"Battery-Level\", args = { min = nan } }]\n",
            "",
            "",
            "an argument must be a name or a finite number",
        ),
        (
            "goal = [{ if = \"Battery-Level\", args = { min = 150 } }]\n",
            "",
            "",
            "`min` of `Battery-Level` must be a percentage from 0 to 100, found 150",
        ),
        (
            "goal = [{ if = \"Battery-Level\", args = { min = -inf } }]\n",
            "",
            "",
            "s.toml:1:48",
        ),
    ]);
}

/// The bindings are positioned by reading the policy again, bounded by
/// --max-file-bytes (it was `read_to_string`, which `/dev/zero` fills).
#[test]
fn bindings_are_positioned_by_a_bounded_read() {
    let s = parse_text(&format!("[world]\n{CUBE}{ONE_POLICY}")).expect("valid");
    let policy = btfsm_format::load(
        Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../policies/paper/fig01-bt.toml"
        )),
        &Limits::default(),
    )
    .expect("fig01")
    .policy;
    let mut world = s.world.clone();
    world.objects.clear();
    let world = World::new(
        (*world.layout).clone(),
        world.params.clone(),
        world.robot,
        vec![],
    );
    let limits = Limits {
        max_file_bytes: 4096,
        ..Limits::default()
    };
    let mut diags = Vec::new();
    check_bindings(&policy, "/dev/zero", &limits, &world, &mut diags);
    assert!(!diags.is_empty());
    assert!(diags.iter().all(|d| d.file.is_none()), "{diags:?}");
    let mut diags = Vec::new();
    check_bindings(
        &policy,
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../policies/paper/fig01-bt.toml"
        ),
        &limits,
        &world,
        &mut diags,
    );
    assert!(
        diags[0].to_string().contains("fig01-bt.toml:9:1"),
        "{}",
        diags[0]
    );
}

#[test]
fn scenarios_are_told_from_policies_by_their_head() {
    assert!(looks_like_scenario(
        "# c\nname = \"x\"\nseed = 1\n\n[world]\nrobot = \"start\"\n"
    ));
    assert!(looks_like_scenario(
        "name = \"x\"\n[[policies]]\nfile = \"a.toml\"\n"
    ));
    assert!(!looks_like_scenario(
        "kind = \"bt\"\nroot = \"r\"\n[nodes]\n"
    ));
    assert!(!looks_like_scenario("name = \"no kind\"\n[nodes]\n"));
    assert!(!looks_like_scenario(""));
}

/// Monte Carlo moves each timed disturbance of the scenario to between
/// half and one and a half times its time, keeping their order: an
/// all-clear at 9 s never comes before the emergency of 5 s it clears
/// (drawn independently, it did in about 1 episode in 60).
#[test]
fn timed_disturbances_keep_their_order_when_jittered() {
    let s = parse_text(
        r#"[world]
objects = { cube2 = { at = "east-table" } }
[[policies]]
file = "../paper/fig01-bt.toml"
[[disturbances]]
at = 9.0
emergency = false
[[disturbances]]
at = 5.0
emergency = true
"#,
    )
    .expect("valid");
    let mut spread = (f64::MAX, 0.0f64);
    for seed in 0..2000 {
        let ds = super::mc::draw(&s, seed);
        let at = |i: usize| match ds[i].when {
            When::At(t) => t,
            _ => unreachable!("timed"),
        };
        let (clear, raise) = (at(0), at(1));
        assert!(
            raise <= clear,
            "seed {seed}: emergency {raise}, all-clear {clear}"
        );
        assert!((2.5..=13.5).contains(&raise) && (2.5..=13.5).contains(&clear));
        spread = (spread.0.min(raise), spread.1.max(clear));
    }
    // Still spread over the whole range.
    assert!(spread.0 < 3.0 && spread.1 > 13.0, "{spread:?}");
}

#[test]
fn duplicate_policy_names_are_told_apart_or_refused() {
    let s = parse_text(
        r#"
[world]
robot = "start"
objects = { cube2 = { at = "east-table" } }
[[policies]]
file = "../paper/fig01-bt.toml"
[[policies]]
file = "../paper/fig01-bt.toml"
after_failure = "stop"
[[policies]]
file = "../paper/fig01-bt.toml"
name = "fig01-bt#2b"
"#,
    )
    .unwrap();
    let names: Vec<&str> = s.policies.iter().map(|p| p.policy.name.as_str()).collect();
    assert_eq!(
        names,
        ["Fig. 1 BT baseline", "Fig. 1 BT baseline#2", "fig01-bt#2b"]
    );
    let w: Vec<String> = s.warnings.iter().map(|d| d.to_string()).collect();
    assert!(
        w.iter()
            .any(|w| w.contains("reported as `Fig. 1 BT baseline#2`")),
        "{w:?}"
    );
    let e = parse_text(
        r#"
[world]
robot = "start"
objects = { cube2 = { at = "east-table" } }
[[policies]]
file = "../paper/fig01-bt.toml"
name = "a"
[[policies]]
file = "../paper/fig02-fsm.toml"
name = "a"
"#,
    )
    .unwrap_err();
    let all: String = e.iter().map(|d| d.to_string()).collect();
    assert!(all.contains("two policies are named `a`"), "{all}");
}
