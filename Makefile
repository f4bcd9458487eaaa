# btfsm: `make run` runs the main job on the bundled policies and scenarios,
# `make test` is what CI runs.
CARGO ?= cargo
TARGET_DIR := $(or $(CARGO_TARGET_DIR),target)
BIN := $(TARGET_DIR)/release/btfsm
VENV := .venv
POLICIES := $(wildcard policies/paper/*.toml)
SCENARIOS := $(wildcard policies/scenarios/*.toml)

.PHONY: prerequisites build run test bench bench-ged bench-ted clean paper-docs fuzz mermaid-oracle man differential browser-test view-screenshots wheel packaging

build:
	$(CARGO) build --release --locked

run: build
	$(BIN) paper
	@mkdir -p out
	$(BIN) analyze $(POLICIES)
	$(BIN) analyze $(POLICIES) --format json > out/analysis.json
	@for f in $(POLICIES); do \
	  b=$$(basename $$f .toml); \
	  $(BIN) dot $$f -o out/$$b.dot || exit 2; \
	  if command -v dot >/dev/null 2>&1; then $(BIN) dot $$f --render svg -o out/$$b.svg || exit 2; fi; \
	done
	@for s in $(SCENARIOS); do \
	  b=$$(basename $$s .toml); \
	  $(BIN) sim $$s --format json --plot out/sim-$$b.svg > out/sim-$$b.json || exit 2; \
	done
	$(BIN) sim policies/scenarios/exp1-pick-fails.toml
	$(BIN) plan policies/domains/moma.toml -o out/planned
	$(BIN) sim policies/domains/moma-sim.toml --runs 300
	@if command -v dot >/dev/null 2>&1; then echo "wrote out/analysis.json, out/*.dot, out/*.svg, out/sim-*.json and out/planned/"; \
	 else echo "wrote out/analysis.json, out/*.dot, out/sim-*.json, out/sim-*.svg and out/planned/ (install Graphviz for the policy SVGs)"; fi

# The property tests draw their cases from this seed in `make test`, so that
# CI gives one answer for one commit; `make test PROPTEST_SEED=N` (or plain
# `cargo test`, which draws a new seed each run) explores other cases, and a
# failing case found so goes to proptest-regressions/ and is kept.
PROPTEST_SEED ?= 20261123

# What `make test` needs besides Rust, checked before anything runs, with
# one message naming each missing program: Graphviz's dot (SVG rendering and
# `btfsm view`), Python 3 with venv (the differential oracles), Node.js and
# npm (Mermaid, the browser test) and Chromium (the browser test).
prerequisites:
	@missing=""; \
	command -v dot >/dev/null 2>&1 || missing="$$missing  Graphviz's dot (apt-get install graphviz)\n"; \
	python3 -c 'import venv, ensurepip' >/dev/null 2>&1 || missing="$$missing  Python 3 with venv (apt-get install python3-venv)\n"; \
	command -v npm >/dev/null 2>&1 || missing="$$missing  Node.js 18+ and npm (apt-get install nodejs npm)\n"; \
	command -v chromium >/dev/null 2>&1 || missing="$$missing  Chromium (apt-get install chromium)\n"; \
	if [ -n "$$missing" ]; then printf "make test needs programs that are not installed:\n$$missing(.ci/run installs them with apt-get)\n" >&2; exit 2; fi

# The workspace's rules (ARCHITECTURE.md, "Rules"): formatting, clippy with
# the `[workspace.lints]` table and `-D warnings`, the docs with warnings
# denied, and the tests with and without the default features.
test: prerequisites
	$(CARGO) fmt --all --check
	$(CARGO) clippy --workspace --all-targets --locked -- -D warnings
	RUSTDOCFLAGS="-D warnings" $(CARGO) doc --workspace --no-deps --locked
	PROPTEST_RNG_SEED=$(PROPTEST_SEED) $(CARGO) test --workspace --locked
	PROPTEST_RNG_SEED=$(PROPTEST_SEED) $(CARGO) test --locked -p btfsm -p btfsm-log --no-default-features
	$(CARGO) test --locked --bench scale --bench ged --bench sim --bench ted --bench log -- --test
	$(CARGO) run --quiet --locked -- paper --check
	$(MAKE) --no-print-directory mermaid-oracle
	$(MAKE) --no-print-directory differential
	$(MAKE) --no-print-directory browser-test
	$(MAKE) --no-print-directory packaging

# `btfsm tick` against BehaviorTree.CPP 4 (behaviortreepy, pinned in
# tests/differential/requirements.txt, installed into .venv) on 3000 seeded
# random trees (docs/bt-semantics.md); then every BT XML fixture accepted or
# rejected by both engines alike, and every export loading in BT.CPP with
# the same shape (tests/differential/accept_btcpp.py; known, explained
# mismatches in accept_btcpp_known.txt, which must not go stale); then the
# trees of every project folder of tests/fixtures/btcpp-projects/, whose
# SubTrees are spread over files given together (projects_btcpp.py); every
# FlexBE behavior fixture btfsm loads, built by Python running its
# `create()` with stand-ins for flexbe_core and agreeing with btfsm's TOML
# export state by state (flexbe_exec.py); every
# SARIF log of `lint` against the official schema (sarif_check.py); which
# problems BehaviorTree.CPP meets at creation and which at the first tick, as
# `lint` reports them (btcpp_when.py); the
# port rules of `lint` against BehaviorTree.CPP 4 creating 1000 seeded
# random trees (dataflow_btcpp.py); every JUnit report of `lint` read by
# `junitparser` and `colcon test-result` as CI reads it (junit_check.py); logs
# BehaviorTree.CPP writes, read exactly by `log report` (btlog_check.py) and
# compared by `log compare` as its Python leaves saw them (btlog_compare.py),
# and as SqliteLogger .db3 sessions counted by SQL (btlog_db3.py); every
# markdown output (compare, sim --runs, log report, log compare) of seeded
# random hostile names rendered by cmark-gfm (PyPI `cmarkgfm`, GitHub's
# fork) with no element, link, mention or heading from input
# (markdown_gfm.py); and
# every corpus SCXML file read by btfsm and by an independent SCXML engine
# (PyPI `scjson`) alike (tests/differential/scxml_engine.py); and
# `compare --mode tree`'s distance against the `apted` and `zss` packages on
# 3000 seeded random tree pairs (tests/differential/ted.py).
$(VENV)/.installed: tests/differential/requirements.txt
	python3 -m venv $(VENV)
	$(VENV)/bin/pip install --quiet --disable-pip-version-check -r tests/differential/requirements.txt
	touch $@

differential: $(VENV)/.installed
	$(CARGO) build --quiet --locked
	$(VENV)/bin/python tests/differential/differential.py $(TARGET_DIR)/debug/btfsm --trees 3000
	$(VENV)/bin/python tests/differential/ted.py $(TARGET_DIR)/debug/btfsm --pairs 3000
	@mkdir -p $(TARGET_DIR)
	$(VENV)/bin/python tests/differential/accept_btcpp.py --btfsm $(TARGET_DIR)/debug/btfsm > $(TARGET_DIR)/accept_btcpp.txt 2>&1 \
	  || { tail -40 $(TARGET_DIR)/accept_btcpp.txt; exit 1; }
	@grep -m1 "fixture files" $(TARGET_DIR)/accept_btcpp.txt
	$(VENV)/bin/python tests/differential/projects_btcpp.py --btfsm $(TARGET_DIR)/debug/btfsm > $(TARGET_DIR)/projects_btcpp.txt 2>&1 \
	  || { cat $(TARGET_DIR)/projects_btcpp.txt; exit 1; }
	@tail -1 $(TARGET_DIR)/projects_btcpp.txt
	$(VENV)/bin/python tests/differential/flexbe_exec.py --btfsm $(TARGET_DIR)/debug/btfsm > $(TARGET_DIR)/flexbe_exec.txt 2>&1 \
	  || { cat $(TARGET_DIR)/flexbe_exec.txt; exit 1; }
	@tail -1 $(TARGET_DIR)/flexbe_exec.txt
	$(VENV)/bin/python tests/differential/sarif_check.py --btfsm $(TARGET_DIR)/debug/btfsm
	$(VENV)/bin/python tests/differential/junit_check.py --btfsm $(TARGET_DIR)/debug/btfsm
	$(VENV)/bin/python tests/differential/btcpp_when.py --btfsm $(TARGET_DIR)/debug/btfsm
	$(VENV)/bin/python tests/differential/dataflow_btcpp.py --btfsm $(TARGET_DIR)/debug/btfsm --trees 1000 > $(TARGET_DIR)/dataflow_btcpp.txt 2>&1 \
	  || { grep -v '^Warnings\|^Please' $(TARGET_DIR)/dataflow_btcpp.txt | tail -40; exit 1; }
	@tail -1 $(TARGET_DIR)/dataflow_btcpp.txt
	$(VENV)/bin/python tests/differential/btlog_check.py --btfsm $(TARGET_DIR)/debug/btfsm > $(TARGET_DIR)/btlog_check.txt 2>&1 \
	  || { grep -v '^Warnings\|^Please' $(TARGET_DIR)/btlog_check.txt | tail -40; exit 1; }
	@tail -1 $(TARGET_DIR)/btlog_check.txt
	$(VENV)/bin/python tests/differential/btlog_compare.py --btfsm $(TARGET_DIR)/debug/btfsm > $(TARGET_DIR)/btlog_compare.txt 2>&1 \
	  || { grep -v '^Warnings\|^Please' $(TARGET_DIR)/btlog_compare.txt | tail -40; exit 1; }
	@tail -1 $(TARGET_DIR)/btlog_compare.txt
	$(VENV)/bin/python tests/differential/btlog_db3.py --btfsm $(TARGET_DIR)/debug/btfsm
	$(VENV)/bin/python tests/differential/markdown_gfm.py --btfsm $(TARGET_DIR)/debug/btfsm --cases 150 --seed $(PROPTEST_SEED)
	$(VENV)/bin/python tests/differential/scxml_engine.py $(TARGET_DIR)/debug/btfsm $$(find tests/fixtures/corpus/scxml -name '*.scxml' | sort)
	GED_DUMP=$(abspath $(TARGET_DIR))/paper-graphs.jsonl GED_DUMP_FILES=$(GED_PAPER_FILES) \
	  $(CARGO) test --quiet --locked -p btfsm-metrics --lib dump_policy_graphs -- --ignored > /dev/null
	$(VENV)/bin/python tests/differential/ged_highs.py $(TARGET_DIR)/debug/btfsm --pairs 24 \
	  --shapes tree-edit,fsm-edit3,fsm-edit8,scxml-1-2 --paper $(TARGET_DIR)/paper-graphs.jsonl

# The paper's dense FSMs (and Fig. 6's HFSM) whose pairs ged_highs.py also
# checks against HiGHS: every pair of them, both modes.
GED_PAPER_FILES := policies/paper/fig16b-fsm.toml,policies/paper/fig08e-fsm.toml,policies/paper/fig09b-fsm.toml,policies/paper/fig06-hfsm.toml,policies/paper/fig08d-fsm.toml,policies/paper/scal-fsm.toml,policies/paper/fig15-fsm.toml

# `pip install btfsm`: the wheel of pyproject.toml (maturin, `bindings =
# "bin"`), built into $(TARGET_DIR)/wheels with the same target folder, so
# after `make build` it only packs the binary. The tools of `make packaging`
# (maturin, pre-commit, actionlint, zizmor) are pinned in
# tests/packaging/requirements.txt and installed into .venv.
$(VENV)/.packaging: tests/packaging/requirements.txt | $(VENV)/.installed
	$(VENV)/bin/pip install --quiet --disable-pip-version-check -r tests/packaging/requirements.txt
	touch $@

wheel: $(VENV)/.packaging
	@rm -f $(TARGET_DIR)/wheels/btfsm-*.whl
	@t0=$$(date +%s); \
	CARGO_TARGET_DIR=$(abspath $(TARGET_DIR)) $(VENV)/bin/maturin build --quiet --release --locked --out $(TARGET_DIR)/wheels \
	  && echo "wheel: built in $$(( $$(date +%s) - t0 )) s"

# The wheel installed into a fresh venv and run with no Rust toolchain on
# PATH (tests/packaging/wheel.sh); the GitHub Action and the example
# workflow checked by actionlint and zizmor, and action/review.sh run
# against a local repository with a fake `gh` (tests/packaging/action.sh);
# the pre-commit hooks run by `pre-commit run` on temporary repositories
# (tests/packaging/precommit.sh; pip builds the package there once, with
# this target folder, so only btfsm's own crates are compiled again); the
# wheel's Python module `btfsm` with py_trees (tests/packaging/
# requirements-python.txt) and SMACH's core (tests/fixtures/smach/):
# the paper's Figs. 1, 2 and 4 written in py_trees and SMACH exported and
# checked against policies/paper/ (tests/packaging/python_export.py).
packaging: build wheel
	tests/packaging/wheel.sh $(TARGET_DIR)/wheels
	python3 tests/packaging/python_export.py $(TARGET_DIR)/wheels
	tests/packaging/action.sh $(VENV)/bin $(BIN)
	CARGO_TARGET_DIR=$(abspath $(TARGET_DIR)) tests/packaging/precommit.sh $(VENV)/bin/pre-commit

# `convert --to mermaid` parsed by Mermaid itself (npm packages pinned in
# tests/differential/mermaid/package-lock.json; needs Node.js 18+ and npm).
NAV2 := tests/fixtures/corpus/bt-xml/nav2
mermaid-oracle: build
	cd tests/differential/mermaid && npm ci --silent --no-audit --no-fund
	node tests/differential/mermaid/check.mjs $(BIN) -- tests/differential/mermaid/labels-*.toml \
	  policies/paper/*.toml $$(find tests/fixtures/corpus -name '*.scxml') \
	  $$(find tests/fixtures/corpus/yasmin -name '*.xml')
	node tests/differential/mermaid/check.mjs $(BIN) --nodes-model $(NAV2)/nav2_tree_nodes.xml -- \
	  $$(ls $(NAV2)/*.xml | grep -v tree_nodes) tests/fixtures/corpus/bt-xml/btcpp/parent_include_child.xml
	node tests/differential/mermaid/check_diff.mjs $(BIN) $(DIFF_PAIRS)

# Pairs whose `compare --format markdown` diff diagram Mermaid must parse
# (check_diff.mjs): reorder, BT insertion, FSM edits with guards, hostile
# labels both ways, HFSM, and policies of different kinds.
DP := policies/paper
DM := tests/differential/mermaid
DIFF_PAIRS := $(DP)/fig01-bt.toml $(DP)/fig03-bt.toml $(DP)/fig07a-bt.toml $(DP)/fig07b-bt.toml \
  $(DP)/fig07b-bt.toml $(DP)/fig07e-bt.toml $(DP)/fig08a-fsm.toml $(DP)/fig08b-fsm.toml \
  $(DP)/fig08b-fsm.toml $(DP)/fig08d-fsm.toml $(DP)/fig04-fsm.toml $(DP)/fig09b-fsm.toml \
  $(DM)/labels-bt.toml $(DP)/fig01-bt.toml $(DP)/fig01-bt.toml $(DM)/labels-bt.toml \
  $(DM)/labels-fsm.toml $(DP)/fig04-fsm.toml $(DP)/fig04-fsm.toml $(DM)/labels-fsm.toml \
  $(DP)/fig06-hfsm.toml $(DP)/fig05-bt.toml $(DP)/fig01-bt.toml $(DP)/fig06-hfsm.toml

# `btfsm view` pages driven in headless Chromium (Debian package `chromium`;
# puppeteer-core pinned in tests/browser/package-lock.json; Node.js 18+):
# every bundled scenario, the two BT.CPP logs, a .db3 and the hostile-names
# scenario, each node's fill at each step reached checked against
# `dot --trace` / `log dot` drawings of that step; the 10,000-step page's
# size, load and jump times printed (docs/view.md). Pages and screenshots in
# $(TARGET_DIR)/view-browser/.
VIEW_LOGS := tests/fixtures/logs/fig01.btlog tests/fixtures/logs/subtree.btlog tests/fixtures/logs/sessions.db3
browser-test: build
	cd tests/browser && npm ci --silent --no-audit --no-fund
	node tests/browser/view.mjs --btfsm $(BIN) --out $(TARGET_DIR)/view-browser \
	  --scale tests/fixtures/view/five-cubes-10k.toml $(addprefix --log ,$(VIEW_LOGS)) \
	  $(SCENARIOS) tests/fixtures/view/hostile.toml

# The README's screenshots of a replay page (docs/img/view-*.png).
view-screenshots: build
	cd tests/browser && npm ci --silent --no-audit --no-fund
	node tests/browser/view.mjs --btfsm $(BIN) --out $(TARGET_DIR)/view-browser \
	  --screenshots docs/img policies/scenarios/exp1-pick-fails.toml

# Man pages from the argument definitions: target/man/btfsm.1 and one
# btfsm-SUBCOMMAND.1 per subcommand (`man -l target/man/btfsm.1`).
man: build
	@mkdir -p target/man
	$(BIN) man > target/man/btfsm.1
	@for c in $$($(BIN) --help | sed -n '/^Commands:/,/^$$/p' | awk 'NR>1 && $$1 != "help" {print $$1}'); do \
	  $(BIN) man $$c > target/man/btfsm-$$c.1 || exit 2; \
	done
	@echo "wrote target/man/btfsm*.1"

# Regenerates docs/paper-results.md (a test fails when it is stale).
paper-docs:
	$(CARGO) run --quiet --locked -- paper --format markdown -o docs/paper-results.md

bench: build
	$(CARGO) bench --locked

# btfsm vs NetworkX, then vs HiGHS (highspy, the exact MIP oracle of
# `make differential`), each on the same GED pairs in one run
# (docs/performance.md).
bench-ged: $(VENV)/.installed
	python3 bench/ged_vs_networkx.py
	$(CARGO) build --quiet --locked --release
	$(VENV)/bin/python bench/ged_vs_highs.py $(BIN)

# btfsm's tree edit distance vs the `apted` package on the same pairs, then
# vs the compiled `edist` on unrelated 1k/5k/10k-node trees, in one run
# (docs/performance.md); uses .venv (make differential creates it).
bench-ted: $(VENV)/.installed
	$(CARGO) build --release --locked
	$(VENV)/bin/python bench/ted_vs_apted.py $(BIN)
	$(VENV)/bin/python bench/ted_vs_edist.py $(BIN)

# Each fuzz target for FUZZ_SECONDS (default 600) with cargo-fuzz on nightly
# (docs/robustness.md); FUZZ_TARGETS="toml_policy" runs only some.
FUZZ_SECONDS ?= 600
fuzz:
	FUZZ_SECONDS=$(FUZZ_SECONDS) ./fuzz/run.sh $(FUZZ_TARGETS)

clean:
	rm -rf out
	$(CARGO) clean
