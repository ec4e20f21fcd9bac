#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# SPDX licence identifiers of the source files (every tracked C/C++, Python, CMake, shell and Make
# file; documents, JSON and binary assets carry none).
#   scripts/spdx.sh --check [DIR]   lists the files without an SPDX-License-Identifier line; exit 1 if any
#   scripts/spdx.sh --fix [DIR]     adds the line in the comment form of each file type (after a shebang)
# DIR defaults to the repository this script belongs to.
set -euo pipefail
mode=${1:-}
root=${2:-"$(cd "$(dirname "$0")/.." && pwd)"}
tag="SPDX-License-Identifier: Apache-2.0"
if [[ "$mode" != "--check" && "$mode" != "--fix" ]]; then
  echo "usage: scripts/spdx.sh --check|--fix [DIR]" >&2
  exit 64
fi
cd "$root"

# The comment leader of a file, or nothing when the file type carries no identifier.
leader() {
  local f=$1 base=${1##*/}
  case "$base" in
    *.c | *.cc | *.cpp | *.h | *.hpp | *.inc | *.h.in) echo "//" ;;
    *.py | *.cmake | *.cmake.in | CMakeLists.txt | *.sh | Makefile | *.mk) echo "#" ;;
    *.*) ;;
    *) head -c 2 "$f" 2>/dev/null | grep -q '^#!' && echo "#" ;;
  esac
}

if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files --cached --others --exclude-standard)
else
  mapfile -t files < <(find . -type f -not -path './build*' -not -path './.git/*' | sed 's|^\./||')
fi

missing=0
for f in "${files[@]}"; do
  [[ -f "$f" ]] || continue
  [[ "$f" == .* ]] && continue  # hidden folders (CI entry points) and dot files are not sources
  lead=$(leader "$f") || true
  [[ -n "$lead" ]] || continue
  head -n 5 "$f" | grep -q "SPDX-License-Identifier:" && continue
  if [[ "$mode" == "--check" ]]; then
    echo "$f"
    missing=$((missing + 1))
    continue
  fi
  tmp=$(mktemp)
  if head -n 1 "$f" | grep -q '^#!'; then
    { head -n 1 "$f"; echo "$lead $tag"; tail -n +2 "$f"; } >"$tmp"
  else
    { echo "$lead $tag"; cat "$f"; } >"$tmp"
  fi
  chmod --reference="$f" "$tmp"
  mv "$tmp" "$f"
done
if [[ "$mode" == "--check" && $missing -gt 0 ]]; then
  echo "spdx: $missing file(s) without '$tag'" >&2
  exit 1
fi
exit 0
