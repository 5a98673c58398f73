#!/usr/bin/env bash
# Install contactfx on Debian 12 (bookworm, dolfinx 0.5) or Debian 13 (trixie, dolfinx 0.9):
#   1. the system packages from apt (FEniCSx, gmsh, Open MPI, OpenBLAS, pytest, ...), only the
#      missing ones;
#   2. a virtual environment ./.venv (repo root) that sees the Debian packages
#      (--system-site-packages) with contactfx installed editable, redone only when
#      pyproject.toml changed;
#   3. a check that dolfinx, gmsh and contactfx import.
# Idempotent: a second run installs nothing and says so. Run as root or as a user with sudo.
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
VENV="$ROOT/.venv"
STAMP="$VENV/.contactfx-install-stamp"
# The interpreter that sees Debian's python3-* packages (not a pyenv/conda python3 on PATH).
SYSPY=/usr/bin/python3

APT_PACKAGES=(
    python3-dolfinx python3-gmsh python3-pytest python3-matplotlib
    python3-h5py-mpi            # the XDMF output: every rank writes its rows of the HDF5 file
    python3-scipy               # the contact search (k-d trees) and the mesh partition (RCM)
    python3-pytest-xdist        # the serial test session on every core (make test)
    python3-venv python3-pip python3-setuptools python3-wheel
    openmpi-bin openssh-client  # mpirun refuses to start without an rsh/ssh agent on PATH
    libopenblas0-pthread        # PETSc/MUMPS through OpenBLAS instead of reference BLAS
    make git
)

say() { printf 'install.sh: %s\n' "$*"; }
die() { printf 'install.sh: error: %s\n' "$*" >&2; exit 1; }

# --- 0. supported system -------------------------------------------------------------------
os_id=unknown os_version=unknown os_name="unknown system"
if [[ -r /etc/os-release ]]; then
    # shellcheck disable=SC1091
    os_id=$(. /etc/os-release && echo "${ID:-unknown}")
    os_version=$(. /etc/os-release && echo "${VERSION_ID:-${VERSION_CODENAME:-unknown}}")
    os_name=$(. /etc/os-release && echo "${PRETTY_NAME:-$os_id $os_version}")
fi
case "$os_id:$os_version" in
    debian:12 | debian:bookworm | debian:13 | debian:trixie) ;;
    *) die "unsupported system '$os_name': contactfx installs on Debian 12 (bookworm) or 13 (trixie) only" ;;
esac

if [[ $EUID -eq 0 ]]; then
    SUDO=()
elif command -v sudo >/dev/null 2>&1; then
    SUDO=(sudo)
else
    SUDO=()  # only fails if something must be installed
fi

# --- 1. apt packages -----------------------------------------------------------------------
missing=()
installed=$(dpkg-query -W -f='${Package} ${db:Status-Abbrev}\n' "${APT_PACKAGES[@]}" 2>/dev/null || true)
for pkg in "${APT_PACKAGES[@]}"; do
    grep -qxF "$pkg ii " <<<"$installed" || missing+=("$pkg")
done
if ((${#missing[@]})); then
    if [[ $EUID -ne 0 && ${#SUDO[@]} -eq 0 ]]; then
        die "missing apt packages (${missing[*]}): run as root or install sudo"
    fi
    say "apt: installing ${#missing[@]} package(s): ${missing[*]}"
    apt_env=(env DEBIAN_FRONTEND=noninteractive)
    "${SUDO[@]}" "${apt_env[@]}" apt-get update -q
    "${SUDO[@]}" "${apt_env[@]}" apt-get install -y -q --no-install-recommends \
        -o Dpkg::Options::=--force-confdef -o Dpkg::Options::=--force-confold "${missing[@]}"
else
    say "apt: all ${#APT_PACKAGES[@]} packages already installed, nothing to do"
fi

# --- 2. virtual environment + editable install ---------------------------------------------
# Run as root on a checkout owned by someone else (e.g. `sudo scripts/install.sh`): build the
# venv as the checkout's owner, so it stays usable (and removable) without root.
owner=$(stat -c %U "$ROOT")
as_owner=()
if [[ $EUID -eq 0 && $owner != root && $owner != UNKNOWN ]]; then
    as_owner=(runuser -u "$owner" -- env HOME="$(getent passwd "$owner" | cut -d: -f6)")
fi

venv_ok() {
    [[ -x $VENV/bin/python && -f $VENV/pyvenv.cfg ]] &&
        grep -qx 'include-system-site-packages = true' "$VENV/pyvenv.cfg" &&
        "$VENV/bin/python" -c 'import sys; sys.exit(sys.base_prefix != "/usr")' 2>/dev/null
}
if venv_ok; then
    say "venv: $VENV exists"
else
    [[ -e $VENV ]] && say "venv: $VENV is not a /usr/bin/python3 --system-site-packages venv, recreating"
    rm -rf "$VENV"
    say "venv: creating $VENV"
    "${as_owner[@]}" "$SYSPY" -m venv --system-site-packages "$VENV"
fi

want=$(sha256sum "$ROOT/pyproject.toml" | cut -d' ' -f1)
have=$(cat "$STAMP" 2>/dev/null || true)
if [[ $want == "$have" ]]; then
    say "pip: pyproject.toml unchanged, contactfx already installed (editable)"
else
    say "pip: installing contactfx (editable) into $VENV"
    (cd "$ROOT" && "${as_owner[@]}" "$VENV/bin/python" -m pip install -q \
        --disable-pip-version-check --no-cache-dir --no-input --no-build-isolation --no-deps -e .)
    "${as_owner[@]}" sh -c 'printf "%s\n" "$1" > "$2"' _ "$want" "$STAMP"
fi

# --- 3. check (from / so that contactfx comes from the editable install, not the cwd) ------
if ! versions=$(cd / && "$VENV/bin/python" -c '
import dolfinx, gmsh, contactfx
from contactfx.io.xdmf import h5py_mpi
h5py = h5py_mpi()
print(f"dolfinx {dolfinx.__version__}, gmsh {gmsh.__version__}, h5py {h5py.__version__} (MPI), "
      f"contactfx from {contactfx.__path__[0]}")'); then
    rm -f "$STAMP"  # the next run reinstalls
    die "the check 'import dolfinx, gmsh, contactfx, h5py (MPI)' failed in $VENV"
fi
say "ok ($os_name): $versions"
