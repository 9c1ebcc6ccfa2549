#!/usr/bin/env bash
# Lists the C++ files that do not follow .clang-format and exits 1 when there is one; with --fix, formats them.
# A developer tool: needs clang-format (apt-get install clang-format; the code was formatted with version 14).
set -euo pipefail
cd "$(dirname "$0")/.."
command -v clang-format > /dev/null || { echo "check-format.sh: clang-format is not installed" >&2; exit 2; }
if [[ "${1:-}" == "--fix" ]]; then
  git ls-files '*.cc' '*.h' | xargs clang-format -i
  exit 0
fi
status=0
while IFS= read -r file; do
  if ! clang-format --dry-run -Werror "$file" > /dev/null 2>&1; then
    echo "$file"
    status=1
  fi
done < <(git ls-files '*.cc' '*.h')
exit $status
