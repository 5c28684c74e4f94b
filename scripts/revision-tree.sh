# Sourced by the scripts that compare this tree with a revision
# (scripts/check-unchanged.sh, bench/run_parse_bench.sh,
# bench/run_revision_bench.sh): `revision_tree NAME REV` makes a temporary
# folder, exported as $tmp, with REV checked out in $tmp/tree (a detached
# `git worktree`), and removes both on exit or on a signal. Exits 2 when
# there is no revision REV.
revision_tree() { # NAME REV
  tmp=$(mktemp -d "/tmp/libblend-$1.XXXXXX")
  trap 'git worktree remove --force "$tmp/tree" >/dev/null 2>&1 || true; rm -rf "$tmp"' EXIT
  trap 'exit 130' INT TERM
  git worktree add --detach "$tmp/tree" "$2" >/dev/null 2>&1 ||
    { echo "$1: no revision $2" >&2; exit 2; }
}
