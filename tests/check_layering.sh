#!/usr/bin/env bash
# Checks docs/architecture.md's dependency table: no file of a module includes a header of a
# module it may not use. Prints each offending include and exits 1 if there is any.
set -euo pipefail
root="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
declare -A allowed=(
  [core]="core"
  [imageio]="core imageio"
  [features]="core features"
  [optimize]="core optimize"
  [bal]="core optimize bal"
  [direct]="core imageio optimize direct"
  [pipeline]="core imageio features optimize pipeline"
  [evaluation]="core imageio features optimize pipeline evaluation"
  [synthetic]="core imageio features optimize synthetic"
)
bad=0
checked=0
for module in "${!allowed[@]}"; do
  while IFS= read -r line; do
    file="${line%%:*}"
    used="$(sed -E 's#.*pnpba/([a-z_]+)/.*#\1#' <<<"$line")"
    checked=$((checked + 1))
    if ! grep -qw "$used" <<<"${allowed[$module]}"; then
      echo "layering: ${file#$root/} ($module) includes pnpba/$used/"
      bad=1
    fi
  done < <(grep -rnE '#include [<"]pnpba/[a-z_]+/' "$root/$module" || true)
done
# Heavy headers stay out of public headers.
if grep -rnE '#include [<"](ceres|open3d|Open3D|pcl)/' "$root"/*/include; then
  echo "layering: a public header includes Ceres, Open3D or PCL"
  bad=1
fi
echo "layering: $checked includes checked"
exit $bad
