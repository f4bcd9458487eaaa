#!/usr/bin/env bash
# The GitHub Action's install step (action.yml): btfsm into a venv of its
# own under $RUNNER_TEMP (a runner's system Python refuses `pip install`,
# PEP 668), its bin folder added to $GITHUB_PATH. INPUT_INSTALL empty: the
# action's own checkout ($ACTION_PATH), built by pip -> maturin -> cargo;
# else what pip is given (a wheel's path, `btfsm==VERSION`).
set -euo pipefail
venv=${RUNNER_TEMP:?}/btfsm-venv
python3 -m venv "$venv"
if [ -n "${INPUT_INSTALL:-}" ]; then
  "$venv/bin/pip" install --disable-pip-version-check --quiet -- "$INPUT_INSTALL"
else
  "$venv/bin/pip" install --disable-pip-version-check --quiet -- "${ACTION_PATH:?}"
fi
echo "$venv/bin" >>"${GITHUB_PATH:?}"
"$venv/bin/btfsm" --version
