#!/usr/bin/env bash
# Comment-ready Markdown comparing every spec that a pull request changes with the base branch:
# one `balpipe diff BASE:OLD_PATH NEW_PATH -f markdown` per modified or renamed spec, a line for
# each added or removed one.
#
# usage: pr-diff.sh BASE_REV OUT.md [balpipe diff options, e.g. --no-sim]
# env:   SPECS (folder of the specs, default specs), PYTHON (default python)
set -euo pipefail

if [ $# -lt 2 ]; then
  echo "usage: $0 BASE_REV OUT.md [balpipe diff options]" >&2
  exit 2
fi
base="$1"
out="$2"
shift 2
specs="${SPECS:-specs}"
python="${PYTHON:-python}"
err="$(mktemp)"
trap 'rm -f "$err"' EXIT

changes="$(git diff --name-status -M --diff-filter=ADMR "$base" HEAD -- "$specs/*.yaml" "$specs/*.yml")"

n=0
{
  echo "# balpipe: specs changed by this pull request"
  echo
  if [ -z "$changes" ]; then
    echo "No spec in \`$specs/\` changed (compared with \`$(git rev-parse --short "$base")\`)."
  fi
  while IFS=$'\t' read -r status old new; do
    [ -n "$status" ] || continue
    n=$((n + 1))
    case "$status" in
      A)
        echo "## \`$old\`: new spec"
        echo
        echo "No earlier version to compare with; its page is in the site artifact."
        echo
        ;;
      D)
        echo "## \`$old\`: removed"
        echo
        ;;
      M | R*)
        # balpipe diff writes its own "## balpipe diff: BASE:OLD -> NEW" heading
        if ! "$python" -m balpipe diff "$base:$old" "${new:-$old}" -f markdown "$@" 2>"$err"; then
          echo "## \`${new:-$old}\`: balpipe diff failed"
          echo
          echo '```'
          cat "$err"
          echo '```'
        fi
        echo
        ;;
    esac
  done <<<"$changes"
} >"$out"
echo "pr-diff: $n changed spec(s) -> $out" >&2
