#!/usr/bin/env bash
# Run a command in the Debian 13 container recipe (./Dockerfile) without Docker: a chroot.
#
#   scripts/chroot-debian13.sh [command...]        (default: make test; as root)
#   scripts/chroot-debian13.sh .venv/bin/python -c 'import dolfinx; print(dolfinx.__version__)'
#
# 1. Image, cached: /var/cache/contactfx/trixie-<sha256(scripts/install.sh + Dockerfile)[:12]>.
#    When absent: debootstrap a minbase trixie (what `FROM debian:trixie` is), interpret the
#    Dockerfile's COPY / WORKDIR / ENV / RUN in it with chroot, then rename it into place.
#    Older trixie-<hash> images are removed once the new one is in place.
# 2. Every call: copy the current tree (git ls-files: tracked + untracked-not-ignored, so no
#    .venv or results) fresh into the image (the image's own .venv is kept), replay the
#    Dockerfile (install.sh is idempotent, so this is quick), then run the command in the
#    WORKDIR with the Dockerfile's ENV only. Exits with the command's status.
# Build and replay output goes to stderr, so stdout is the command's own.
# /proc, /sys and /dev are bind-mounted (recursively, as slaves) and always unmounted on exit.
# Environment: CONTACTFX_CACHE (default /var/cache/contactfx), DEBIAN_MIRROR.
set -euo pipefail

SRC=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
DOCKERFILE="$SRC/Dockerfile"
CACHE=${CONTACTFX_CACHE:-/var/cache/contactfx}
MIRROR=${DEBIAN_MIRROR:-http://deb.debian.org/debian}
SUITE=trixie
# What `docker run` starts from in debian:trixie.
BASE_ENV=(PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin HOME=/root)

say() { printf 'chroot-debian13: %s\n' "$*" >&2; }
die() { say "error: $*"; exit 2; }

[[ $EUID -eq 0 ]] || die "must run as root (debootstrap, mount, chroot)"
for tool in debootstrap chroot mount umount findmnt sha256sum tar flock; do
    command -v "$tool" >/dev/null || die "'$tool' not found (apt-get install debootstrap util-linux)"
done
[[ -f $DOCKERFILE ]] || die "no Dockerfile in $SRC"
(($#)) || set -- make test

mkdir -p "$CACHE"
exec 9>"$CACHE/.lock"
flock 9 || die "cannot lock $CACHE/.lock"

hash=$(cat "$SRC/scripts/install.sh" "$DOCKERFILE" | sha256sum | cut -c1-12)
IMAGE="$CACHE/$SUITE-$hash"

# --- mounts, always undone -------------------------------------------------------------------
MOUNTED=()  # rootfs directories with our mounts under them
BUILD_DIR=""

mounts_under() { findmnt -rn -o TARGET | awk -v r="$1" 'index($0, r "/") == 1'; }

kill_chroot_procs() {  # processes left inside the rootfs (e.g. an orphaned MPI daemon)
    local root=$1 p
    for p in /proc/[0-9]*; do
        [[ $(readlink "$p/root" 2>/dev/null) == "$root" ]] && kill -KILL "${p#/proc/}" 2>/dev/null
    done
    return 0
}

unmount_all() {
    local root=$1 d
    kill_chroot_procs "$root"
    for d in dev sys proc; do
        if mountpoint -q "$root/$d"; then
            umount -R "$root/$d" 2>/dev/null || umount -R -l "$root/$d" || true
        fi
    done
    [[ -z $(mounts_under "$root") ]]
}

cleanup() {
    local rc=$? root
    trap - EXIT INT TERM HUP
    for root in "${MOUNTED[@]}"; do
        unmount_all "$root" || say "warning: mounts left under $root"
    done
    if [[ -n $BUILD_DIR && -d $BUILD_DIR ]]; then
        if [[ -z $(mounts_under "$BUILD_DIR") ]]; then
            rm -rf --one-file-system "$BUILD_DIR" "$BUILD_DIR.debootstrap.log"
        else
            say "warning: not removing $BUILD_DIR: still has mounts"
        fi
    fi
    exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
trap 'exit 129' HUP

mount_api() {  # mount_api ROOTFS
    local root=$1 d
    MOUNTED+=("$root")
    for d in proc sys dev; do
        mkdir -p "$root/$d"
        mountpoint -q "$root/$d" && continue
        mount --rbind "/$d" "$root/$d"
        mount --make-rslave "$root/$d"  # unmounting the copy must never unmount the host's
    done
    cp -L /etc/resolv.conf "$root/etc/resolv.conf"
    cp -L /etc/hosts "$root/etc/hosts"
}

# --- the Dockerfile interpreter (FROM, COPY, WORKDIR, ENV, RUN) -------------------------------
tree_files() {  # NUL-separated paths of the build context, relative to $SRC
    local git=(git -C "$SRC" -c safe.directory="$SRC")  # a checkout owned by another user
    if "${git[@]}" rev-parse --is-inside-work-tree >/dev/null 2>&1; then
        "${git[@]}" ls-files -z --cached --others --exclude-standard |
            while IFS= read -r -d '' f; do  # skip tracked files deleted in the work tree
                if [[ -e $SRC/$f || -L $SRC/$f ]]; then printf '%s\0' "$f"; fi
            done
    else
        (cd "$SRC" && find . \( -name .git -o -name .venv -o -name results -o -name __pycache__ \) \
            -prune -o \( -type f -o -type l \) -printf '%P\0')
    fi
}

docker_env=()  # KEY=VALUE, in order
env_set() {
    local kv=$1 key=${1%%=*} i
    for i in "${!docker_env[@]}"; do
        if [[ ${docker_env[i]%%=*} == "$key" ]]; then docker_env[i]=$kv; return; fi
    done
    docker_env+=("$kv")
}

in_chroot() {  # in_chroot ROOTFS WORKDIR command... (Dockerfile ENV only, cwd = WORKDIR)
    local root=$1 wd=$2
    shift 2
    chroot "$root" /usr/bin/env -i "${docker_env[@]}" /bin/sh -c 'cd "$0" && exec "$@"' "$wd" "$@"
}

replay_dockerfile() {  # replay_dockerfile ROOTFS
    local root=$1 line instr args workdir=/ n=0 dest src
    local -a words srcs
    docker_env=("${BASE_ENV[@]}")
    # Join continuation lines, drop comments and blank lines.
    while IFS= read -r -u 3 line; do
        [[ $line =~ ^[[:space:]]*(#|$) ]] && continue
        while [[ $line =~ \\[[:space:]]*$ ]]; do
            line=${line%\\*}
            IFS= read -r -u 3 next || break
            [[ $next =~ ^[[:space:]]*# ]] && continue
            line+=" ${next#"${next%%[![:space:]]*}"}"
        done
        line=${line#"${line%%[![:space:]]*}"}
        instr=${line%%[[:space:]]*}
        args=${line#"$instr"}
        args=${args#"${args%%[![:space:]]*}"}
        instr=${instr^^}
        n=$((n + 1))
        case $instr in
            FROM)
                [[ $args == "debian:$SUITE" ]] || die "Dockerfile: FROM $args: only debian:$SUITE is emulated"
                ;;
            ENV)
                # Word-split and expand ($VAR, ${VAR}, quotes) against the image env so far.
                mapfile -d '' -t words < <(env -i "${docker_env[@]}" /bin/bash -c \
                    'eval "set -- $1" && printf "%s\0" "$@"' _ "$args") || die "Dockerfile: cannot parse ENV $args"
                if ((${#words[@]})) && [[ ${words[0]} != *=* ]]; then  # legacy "ENV KEY value"
                    env_set "${words[0]}=${words[*]:1}"
                else
                    for kv in "${words[@]}"; do env_set "$kv"; done
                fi
                ;;
            WORKDIR)
                [[ $args == /* ]] || args="${workdir%/}/$args"
                workdir=$args
                mkdir -p "$root$workdir"
                ;;
            COPY | ADD)
                [[ $args != -* && $args != \[* ]] || die "Dockerfile: '$instr $args': flags / JSON form not emulated"
                read -r -a words <<<"$args"
                ((${#words[@]} >= 2)) || die "Dockerfile: '$instr $args': needs a source and a destination"
                dest=${words[-1]}
                [[ $dest == /* ]] || dest="${workdir%/}/$dest"
                srcs=("${words[@]:0:${#words[@]}-1}")
                say "step $n: $instr ${srcs[*]} -> $dest"
                mkdir -p "$root$dest"
                if [[ ${srcs[*]} == . ]]; then
                    # The context replaces what the last run copied; the image's .venv stays.
                    find "$root$dest" -mindepth 1 -maxdepth 1 ! -name .venv -exec rm -rf {} +
                    tree_files | tar -C "$SRC" --null -T - -cf - | tar -C "$root$dest" --no-same-owner -xf -
                else
                    for src in "${srcs[@]}"; do
                        [[ -e $SRC/$src ]] || die "Dockerfile: COPY $src: not in the context"
                        cp -a "$SRC/$src" "$root$dest/"
                    done
                fi
                ;;
            RUN)
                [[ $args != \[* ]] || die "Dockerfile: JSON-form RUN not emulated: $args"
                say "step $n: RUN $args"
                in_chroot "$root" "$workdir" /bin/sh -c "$args" </dev/null >&2 ||
                    die "Dockerfile step $n failed: RUN $args"
                ;;
            CMD | ENTRYPOINT | LABEL | EXPOSE | VOLUME | ARG | SHELL | STOPSIGNAL | HEALTHCHECK | USER)
                [[ $instr != USER && $instr != SHELL ]] || die "Dockerfile: $instr is not emulated"
                ;;
            *) die "Dockerfile: unknown instruction $instr" ;;
        esac
    done 3<"$DOCKERFILE"
    WORKDIR=$workdir
}

# --- 1. the image ------------------------------------------------------------------------------
if [[ ! -d $IMAGE ]]; then
    BUILD_DIR=$(mktemp -d "$CACHE/.build-$SUITE-$hash.XXXXXX")
    say "no cached image $IMAGE: building (debootstrap --variant=minbase $SUITE)"
    t0=$SECONDS
    debootstrap --variant=minbase "$SUITE" "$BUILD_DIR" "$MIRROR" >"$BUILD_DIR.debootstrap.log" 2>&1 ||
        { tail -n 20 "$BUILD_DIR.debootstrap.log" >&2; die "debootstrap failed (log above)"; }
    rm -f "$BUILD_DIR.debootstrap.log"
    say "debootstrap: $((SECONDS - t0)) s"
    # As in Docker images: services are never started by package installs.
    printf '#!/bin/sh\nexit 101\n' >"$BUILD_DIR/usr/sbin/policy-rc.d"
    chmod 755 "$BUILD_DIR/usr/sbin/policy-rc.d"
    mount_api "$BUILD_DIR"
    t0=$SECONDS
    replay_dockerfile "$BUILD_DIR"
    say "Dockerfile steps (first install): $((SECONDS - t0)) s"
    unmount_all "$BUILD_DIR" || die "cannot unmount under $BUILD_DIR"
    MOUNTED=()
    mv -T "$BUILD_DIR" "$IMAGE"
    BUILD_DIR=""
    for old in "$CACHE/$SUITE"-????????????; do
        [[ -d $old && $old != "$IMAGE" && -z $(mounts_under "$old") ]] || continue
        say "removing outdated image $old"
        rm -rf --one-file-system "$old"
    done
else
    say "using cached image $IMAGE"
fi

# --- 2. this run -------------------------------------------------------------------------------
mount_api "$IMAGE"
t0=$SECONDS
replay_dockerfile "$IMAGE"
say "Dockerfile steps (replay): $((SECONDS - t0)) s"
say "running in $WORKDIR: $*"
set +e
in_chroot "$IMAGE" "$WORKDIR" "$@"
status=$?
set -e
say "exit status $status"
exit "$status"
