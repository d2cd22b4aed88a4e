#!/usr/bin/env bash
# Runs the walkthrough (docs/guide/walkthrough.md) exactly as documented: every line of its
# ```sh code blocks, in order, each from the walkthrough's root directory (a fresh temporary
# directory holding links to the repository's examples/ and tables/, so that out/ is written
# there and not into the checkout), with a fresh table cache. tests/it/walkthrough.rs runs the
# same lines the same way and checks the results.
#
#   tools/walkthrough.sh [--time] [--keep]
#
#   --time   print, per command, its wall time and its CPU time (user + sys of the command and
#            its children, from /usr/bin/time), and the totals
#   --keep   keep the temporary directory (its path is printed)
#
# The commands find `strata` and `ccx` on PATH; STRATA=/path/to/strata puts that binary first
# (default: `cargo build --release --bin strata`'s, built if missing).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
TIME=0 KEEP=0
for a in "$@"; do
    case "$a" in
        --time) TIME=1 ;;
        --keep) KEEP=1 ;;
        *) echo "usage: tools/walkthrough.sh [--time] [--keep]" >&2; exit 2 ;;
    esac
done
if [ -z "${STRATA:-}" ]; then
    cargo build --release -q --bin strata
    STRATA="${CARGO_TARGET_DIR:-$ROOT/target}/release/strata"
fi
[ "$TIME" = 0 ] || [ -x /usr/bin/time ] || { echo "walkthrough: --time needs /usr/bin/time (apt-get install time)" >&2; exit 1; }
[ -x "$STRATA" ] || { echo "walkthrough: no strata binary at $STRATA" >&2; exit 1; }

WORK=$(mktemp -d)
[ "$KEEP" = 1 ] || trap 'rm -rf "$WORK"' EXIT
mkdir -p "$WORK/bin" "$WORK/root"
ln -s "$(readlink -f "$STRATA")" "$WORK/bin/strata"
ln -s "$ROOT/examples" "$WORK/root/examples"
ln -s "$ROOT/tables" "$WORK/root/tables"
export PATH="$WORK/bin:$PATH" STRATA_CACHE_DIR="$WORK/cache"

# The lines of the ```sh blocks ('\' continuations joined, comments and blank lines dropped).
mapfile -t CMDS < <(awk '
    /^```/ { if (inblock) { inblock = 0 } else if ($0 == "```sh") { inblock = 1 }; next }
    inblock {
        line = line $0
        if (sub(/\\$/, "", line)) next
        sub(/^[ \t]+/, "", line)
        if (line != "" && line !~ /^#/) print line
        line = ""
    }' docs/guide/walkthrough.md)
[ "${#CMDS[@]}" -gt 0 ] || { echo "walkthrough: no commands in docs/guide/walkthrough.md" >&2; exit 1; }

echo "walkthrough: ${#CMDS[@]} commands in $WORK/root (strata: $(readlink -f "$STRATA"); $(nproc) CPUs)"
TOTAL_WALL=0 TOTAL_CPU=0
for c in "${CMDS[@]}"; do
    echo "\$ $c"
    if [ "$TIME" = 1 ]; then
        T=$(mktemp)
        (cd "$WORK/root" && /usr/bin/time -f "%e %U %S" -o "$T" bash -c "$c" >"$WORK/last.log" 2>&1) \
            || { cat "$WORK/last.log"; echo "walkthrough: failed: $c" >&2; exit 1; }
        read -r WALL USR SYS <"$T"; rm -f "$T"
        CPU=$(awk -v a="$USR" -v b="$SYS" 'BEGIN { print a + b }')
        TOTAL_WALL=$(awk -v a="$TOTAL_WALL" -v b="$WALL" 'BEGIN { print a + b }')
        TOTAL_CPU=$(awk -v a="$TOTAL_CPU" -v b="$CPU" 'BEGIN { print a + b }')
        printf '    %8.2f s wall %8.2f CPU-s\n' "$WALL" "$CPU"
    else
        (cd "$WORK/root" && bash -c "$c") || { echo "walkthrough: failed: $c" >&2; exit 1; }
    fi
done
if [ "$TIME" = 1 ]; then
    printf 'walkthrough: total %.2f s wall, %.2f CPU-s (%s CPUs)\n' "$TOTAL_WALL" "$TOTAL_CPU" "$(nproc)"
fi
[ "$KEEP" = 0 ] || echo "walkthrough: outputs kept in $WORK/root/out"
