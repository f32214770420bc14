#!/usr/bin/env bash
# Install what bulkflow needs to build and test, on Debian 12 (as root, or through sudo).
# Idempotent: it checks first and installs only what is missing, so a second run takes well
# under two seconds. Quiet when all goes well; a failing step prints its full log.
#
# Python: the python3 on PATH is the base interpreter. numpy, scipy, matplotlib, h5py and
# pytest go into it (apt for Debian's /usr/bin/python3, pip for any other, e.g. pyenv). The
# project's own package (scripts/pyproject.toml, once it exists) is installed editable into a
# virtual environment .venv/ made from that base with --system-site-packages, which avoids
# pip's --break-system-packages on Debian. Every other script uses .venv/bin/python.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
venv="$repo/.venv"
python_modules=(numpy scipy matplotlib h5py pytest)
apt_packages=(gfortran libopenmpi-dev openmpi-bin libhdf5-openmpi-dev liblapack-dev cmake make
              python3 python3-pip python3-venv pkg-config)

log=$(mktemp)
trap 'rm -f "$log"' EXIT

# Run a command with its output in $log; show the log only if it fails.
quietly() {
  if ! "$@" >"$log" 2>&1; then
    cat "$log" >&2
    echo "setup.sh: failed: $*" >&2
    exit 1
  fi
}

as_root() {
  if [ "$(id -u)" -eq 0 ]; then
    "$@"
  elif command -v sudo >/dev/null 2>&1; then
    sudo "$@"
  else
    echo "setup.sh: need root or sudo to run: $*" >&2
    exit 1
  fi
}

apt_updated=false
apt_install() {
  if ! $apt_updated; then
    quietly as_root apt-get update -qq
    apt_updated=true
  fi
  echo "setup.sh: apt-get install $*"
  quietly as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "$@"
}

# Packages of the list that dpkg does not report as installed.
missing_debian_packages() {
  local installed
  installed=$(dpkg-query -W -f='${Status} ${Package}\n' "$@" 2>/dev/null |
              awk '$3 == "installed" { print $4 }' || true)
  local package
  for package in "$@"; do
    grep -qx "$package" <<<"$installed" || echo "$package"
  done
}

# --- system packages ---------------------------------------------------------------------
if command -v dpkg-query >/dev/null 2>&1; then
  mapfile -t missing < <(missing_debian_packages "${apt_packages[@]}")
  if [ "${#missing[@]}" -gt 0 ]; then
    apt_install "${missing[@]}"
  fi
else
  echo "setup.sh: not a Debian system; make sure these are installed: ${apt_packages[*]}" >&2
fi

# --- base Python and its scientific modules ------------------------------------------------
# The real interpreter behind python3 (pyenv shims and an activated venv resolved).
base=$(python3 -c 'import sys; print(getattr(sys, "_base_executable", sys.executable))')
base=$(readlink -f "$base")

missing_modules() {
  "$1" - "${python_modules[@]}" <<'PY'
import importlib, sys
for name in sys.argv[1:]:
    try:
        importlib.import_module(name)
    except Exception:
        print(name)
PY
}

mapfile -t missing < <(missing_modules "$base")
if [ "${#missing[@]}" -gt 0 ]; then
  if [ "$base" = "$(readlink -f /usr/bin/python3)" ]; then
    apt_install "${missing[@]/#/python3-}"
  else
    echo "setup.sh: pip install ${missing[*]} (for $base)"
    quietly "$base" -m pip install --quiet --disable-pip-version-check "${missing[@]}"
  fi
  mapfile -t still_missing < <(missing_modules "$base")
  if [ "${#still_missing[@]}" -gt 0 ]; then
    echo "setup.sh: $base still cannot import: ${still_missing[*]}" >&2
    exit 1
  fi
fi

# --- the project's virtual environment --------------------------------------------------
# Re-create it when it is broken or was made from another base interpreter.
venv_home=""
if [ -f "$venv/pyvenv.cfg" ]; then
  venv_home=$(sed -n 's/^home *= *//p' "$venv/pyvenv.cfg")
fi
if [ ! -x "$venv/bin/python" ] || [ "$(readlink -f "$venv_home")" != "$(dirname "$base")" ] ||
   ! "$venv/bin/python" -c '' >/dev/null 2>&1; then
  rm -rf "$venv"
  echo "setup.sh: creating $venv from $base"
  quietly "$base" -m venv --system-site-packages "$venv"
fi

# The bulkflow Python package, editable; re-installed when its pyproject.toml changes, when a
# console script it declares is missing from .venv/bin, or when `import bulkflow` does not come
# from this checkout (e.g. a .venv copied from another worktree).
editable_install_stale() {
  "$venv/bin/python" - "$repo/scripts" "$venv/bin" <<'PY'
import pathlib, re, sys
scripts, bindir = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
text = (scripts / "pyproject.toml").read_text()
section = re.search(r"^\[project\.scripts\]\s*$(.*?)(?=^\[|\Z)", text, re.M | re.S)
names = re.findall(r"^\s*([A-Za-z0-9_.-]+)\s*=", section.group(1), re.M) if section else []
missing = [n for n in names if not (bindir / n).exists()]
try:
    import bulkflow
    here = pathlib.Path(bulkflow.__file__).resolve().parent == (scripts / "bulkflow").resolve()
except Exception:
    here = False
sys.exit(0 if missing or not here else 1)
PY
}
if [ -f "$repo/scripts/pyproject.toml" ]; then
  stamp="$venv/.bulkflow-pyproject.sha256"
  wanted=$(sha256sum "$repo/scripts/pyproject.toml" | cut -d' ' -f1)
  if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$wanted" ] || editable_install_stale; then
    echo "setup.sh: pip install -e scripts/ (into $venv)"
    quietly "$venv/bin/python" -m pip install --quiet --disable-pip-version-check -e "$repo/scripts"
    echo "$wanted" >"$stamp"
  fi
fi

echo "setup.sh: python: $venv/bin/python (base $base)"
