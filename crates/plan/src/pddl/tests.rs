//! The PDDL reader: the durative-action mapping, typing, constants, the
//! checks of predicates, requirements and groundings, each error at its
//! position.

use super::*;

fn load_str(domain: &str, problem: Option<&str>) -> Result<Domain, Vec<Diagnostic>> {
    let d = SourceFile::new("d.pddl", domain);
    let p = problem.map(|t| SourceFile::new("p.pddl", t));
    load(&d, p.as_ref())
}

fn errors(domain: &str, problem: Option<&str>) -> Vec<String> {
    let e = load_str(domain, problem).expect_err("an error");
    e.iter()
        .map(|d| {
            let (_, l, c) = d.location().unwrap_or_default();
            format!(
                "{l}:{c} {} ({})",
                d.message,
                d.hint.clone().unwrap_or_default()
            )
        })
        .collect()
}

fn facts(ps: &[Pattern]) -> Vec<String> {
    ps.iter()
        .map(|p| format!("{}({})", p.pred, p.args.join(", ")))
        .collect()
}

const DURATIVE: &str = "(define (domain d)
  (:requirements :strips :typing :durative-actions)
  (:types robot room - object)
  (:predicates (at ?r - robot ?x - room) (busy ?r - robot) (free ?r - robot)
               (lit ?x - room) (seen ?x - room))
  (:durative-action go
    :parameters (?r - robot ?a ?b - room)
    :duration (= ?duration 5)
    :condition (and (at start (at ?r ?a)) (over all (lit ?b)) (at end (busy ?r))
                    (at end (seen ?b)))
    :effect (and (at start (not (at ?r ?a))) (at start (busy ?r)) (at end (not (busy ?r)))
                 (at start (not (free ?r))) (at end (free ?r)) (at end (at ?r ?b)))))";

/// At-start and over-all conditions are preconditions, at-end ones too
/// unless an at-start effect adds them; effects are the net change: an
/// at-start add an at-end effect deletes is none, an at-start delete an
/// at-end effect adds is none.
#[test]
fn durative_actions_map_to_their_net_strips_action() {
    let d = load_str(DURATIVE, None).unwrap();
    let a = &d.actions[0];
    assert_eq!(
        facts(&a.pre),
        ["at(r, a)", "lit(b)", "seen(b)"],
        "at end (busy ?r) is added at start"
    );
    assert_eq!(facts(&a.add), ["free(r)", "at(r, b)"]);
    assert_eq!(facts(&a.del), ["at(r, a)", "busy(r)"]);
    assert_eq!(a.cost, 1);
    assert_eq!(a.skill.as_deref(), Some("d:go"));
    assert_eq!(
        a.params.iter().map(|p| &p.ty).collect::<Vec<_>>(),
        ["robot", "room", "room"]
    );
}

#[test]
fn types_constants_and_problem_objects_become_typed_objects() {
    let dom = "(define (domain k) (:requirements :typing)
      (:types part - reachable reachable - location)
      (:constants bench - reachable)
      (:predicates (in ?p - part) (at ?l - location))
      (:action pick :parameters (?p - part) :precondition (at bench) :effect (in ?p)))";
    let prob = "(define (problem p) (:domain k) (:objects bolt - part tray - location)
      (:init (at bench)) (:goal (in bolt)))";
    let d = load_str(dom, Some(prob)).unwrap();
    assert_eq!(
        d.objects["bolt"].types,
        ["part", "reachable", "location", "object"]
    );
    assert_eq!(
        d.objects["bench"].types,
        ["reachable", "location", "object"]
    );
    assert_eq!(d.objects["tray"].types, ["location", "object"]);
    assert_eq!(d.goal.id, "p");
    assert_eq!(d.goal.facts[0].to_string(), "in(bolt)");
    assert_eq!(d.goal.init[0].to_string(), "at(bench)");
    // Without the problem, the objects are the constants and no goal.
    let d = load_str(dom, None).unwrap();
    assert_eq!(d.objects.keys().collect::<Vec<_>>(), ["bench"]);
    assert!(d.goal.facts.is_empty());
}

#[test]
fn an_undeclared_predicate_names_the_declared_one_it_abbreviates() {
    let e = errors(
        "(define (domain f) (:requirements :typing) (:types piece)
          (:predicates (piece_is_wheel ?p - piece) (piece_is_steering_wheel ?p - piece))
          (:action a :parameters (?p - piece)
             :precondition (piece_is_sterwheel ?p) :effect (piece_is_wheel ?p)))",
        None,
    );
    assert_eq!(
        e,
        [
            "4:29 undeclared predicate `piece_is_sterwheel` (did you mean `piece_is_steering_wheel`?)"
        ]
    );
    // A plain misspelling still gets the edit-distance suggestion.
    let e = errors(
        "(define (domain f) (:predicates (robot_at ?x))
          (:action a :parameters (?x) :precondition (robot_ta ?x) :effect (robot_at ?x)))",
        None,
    );
    assert_eq!(
        e,
        ["2:54 undeclared predicate `robot_ta` (did you mean `robot_at`?)"]
    );
}

#[test]
fn unsupported_features_are_refused_where_they_are_used() {
    let dom = |pre: &str, eff: &str| {
        format!(
            "(define (domain f) (:requirements :strips :adl :fluents)
  (:predicates (p ?x) (q ?x))
  (:action a :parameters (?x) :precondition {pre} :effect {eff}))"
        )
    };
    let cases = [
        (
            "(not (p ?x))",
            "(q ?x)",
            "3:45 `not` in a condition needs `:negative-preconditions`",
        ),
        (
            "(or (p ?x) (q ?x))",
            "(q ?x)",
            "3:45 `or` in a condition needs `:disjunctive-preconditions`",
        ),
        (
            "(= ?x ?x)",
            "(q ?x)",
            "3:45 `=` in a condition needs `:equality`",
        ),
        (
            "(p ?x)",
            "(when (p ?x) (q ?x))",
            "3:60 `when` in an effect needs `:conditional-effects`",
        ),
        (
            "(p ?x)",
            "(increase (total-cost) 1)",
            "3:60 `increase` in an effect needs `:numeric-fluents`",
        ),
    ];
    for (pre, eff, want) in cases {
        let e = errors(&dom(pre, eff), None);
        assert_eq!(e.len(), 1, "{e:?}");
        assert!(e[0].starts_with(want), "{} vs {want}", e[0]);
        assert!(
            e[0].contains("which `btfsm plan` does not support"),
            "{}",
            e[0]
        );
    }
    // Declaring them is allowed; an unknown requirement is not.
    let e = errors("(define (domain f) (:requirements :strip))", None);
    assert_eq!(
        e,
        ["1:35 unknown requirement `:strip` (did you mean `:strips`?)"]
    );
    // A durative action and typing need their requirements.
    let e = errors(
        "(define (domain f) (:requirements :strips) (:types a - object))",
        None,
    );
    assert_eq!(e.len(), 1);
    assert!(e[0].starts_with("1:54 `- type` needs `:typing`"), "{e:?}");
}

#[test]
fn terms_are_checked_against_parameters_objects_and_types() {
    let dom = "(define (domain f) (:requirements :typing) (:types robot room)
  (:constants home - room)
  (:predicates (at ?r - robot ?x - room))
  (:action go :parameters (?r - robot ?x - room) :precondition (at ?r ?y)
     :effect (and (at ?x ?r) (at ?r hom) (at ?r))))";
    let e = errors(dom, None);
    assert_eq!(
        e,
        [
            "4:71 `?y` is not a parameter here (did you mean `?r`?)",
            "5:23 `?x` is a `room`; `at` takes a `robot` here (`?r`) (give a `robot`)",
            "5:37 `hom` is not a constant of the domain (did you mean `home`?)",
            "5:42 `at` takes 2 argument(s), found 1 (declared as `(at ?r - robot ?x - room)`)",
        ]
    );
    let prob = "(define (problem p) (:domain g) (:objects r1 - robot) (:init (at r1 r1))
      (:goal (and)))";
    let dom_ok = "(define (domain f) (:requirements :typing) (:types robot room)
      (:predicates (at ?r - robot ?x - room)))";
    let e = errors(dom_ok, Some(prob));
    assert_eq!(
        e[0],
        "1:30 the problem is for domain `g`, not `f` (give the domain file the problem names)"
    );
    assert!(
        e[1].starts_with("1:69 `r1` is a `robot`; `at` takes a `room`"),
        "{e:?}"
    );
}

/// |objects|^arity ground actions: capped before the planner starts.
#[test]
fn groundings_are_capped() {
    let dom = "(define (domain g) (:predicates (p ?a ?b ?c ?d ?e))
      (:action a :parameters (?a ?b ?c ?d ?e) :precondition () :effect (p ?a ?b ?c ?d ?e)))";
    let objects: String = (0..20).map(|i| format!("o{i} ")).collect();
    let prob =
        format!("(define (problem p) (:domain g) (:objects {objects}) (:goal (p o1 o1 o1 o1 o1)))");
    // 20^5 = 3.2 million > 1 million.
    let e = errors(dom, Some(&prob));
    assert_eq!(e.len(), 1);
    assert!(
        e[0].starts_with("2:16 grounding the actions over the objects gives more than 1000000 actions (`a` alone 3200000)"),
        "{e:?}"
    );
    let few: String = (0..10).map(|i| format!("o{i} ")).collect();
    let prob =
        format!("(define (problem p) (:domain g) (:objects {few}) (:goal (p o1 o1 o1 o1 o1)))");
    assert!(load_str(dom, Some(&prob)).is_ok());
}

#[test]
fn pddl_is_told_from_toml_and_atoms_become_fact_text() {
    assert!(looks_like_pddl("x.PDDL", ""));
    assert!(looks_like_pddl("x", "; c\n  ; d\n(define"));
    assert!(!looks_like_pddl("x.toml", "name = \"d\"\n"));
    assert_eq!(
        fact_text("(Robot_At leia  kitchen)"),
        "robot_at(leia, kitchen)"
    );
    assert_eq!(fact_text("(done)"), "done");
    assert_eq!(
        fact_text("Object-At(cube2, delivery)"),
        "Object-At(cube2, delivery)"
    );
}

/// Mutated PlanSys2 domains and problems (characters deleted, doubled or
/// swapped for parentheses, `not`, `?`, `-`; a seeded LCG) load to a
/// domain or to positioned errors, never a panic; what loads plans or
/// reports its cap.
#[test]
fn mutated_domains_and_problems_never_panic() {
    let domain = include_str!("../../../../tests/fixtures/domains/pddl/bt_example.pddl");
    let problem = include_str!("../../../../tests/fixtures/domains/pddl/patrol-problem.pddl");
    let patrol = include_str!("../../../../tests/fixtures/domains/pddl/patrol.pddl");
    let mut seed: u64 = 0x005e_ed0f_9dd1;
    let mut next = move |n: usize| {
        seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        ((seed >> 33) as usize) % n.max(1)
    };
    let pieces = [
        "(", ")", "(not ", "?", " - ", "(and ", " x ", ";", "(at end ",
    ];
    let opts = crate::Options {
        max_nodes: 2_000,
        ..crate::Options::default()
    };
    for round in 0..600 {
        let (d, p) = if round % 2 == 0 {
            (domain, None)
        } else {
            (patrol, Some(problem))
        };
        let target = if round % 4 == 1 { p.unwrap_or(d) } else { d };
        let mut t: Vec<char> = target.chars().collect();
        for _ in 0..1 + next(4) {
            let at = next(t.len());
            match next(3) {
                0 => {
                    t.remove(at);
                }
                1 => t.insert(at, t[at]),
                _ => {
                    let piece = pieces[next(pieces.len())];
                    for (i, c) in piece.chars().enumerate() {
                        t.insert(at + i, c);
                    }
                }
            }
        }
        let mutated: String = t.into_iter().collect();
        let (d, p) = if round % 4 == 1 {
            (d.to_string(), Some(mutated))
        } else {
            (mutated, p.map(str::to_string))
        };
        match load_str(&d, p.as_deref()) {
            Ok(dom) if !dom.goal.facts.is_empty() => {
                let _ = crate::plan_bt(&dom, &opts);
            }
            Ok(_) => {}
            Err(diags) => {
                assert!(!diags.is_empty());
                for x in &diags {
                    assert!(x.file.is_some(), "{}", x.message);
                    assert!(!x.message.is_empty() && x.hint.is_some(), "{}", x.message);
                }
            }
        }
    }
}
