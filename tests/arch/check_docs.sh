#!/usr/bin/env bash
# The docs check (issue 28): what a reader copies from the docs must work.
#  1. Every relative link in README.md, docs/*.md and server/API.md resolves
#     to a file, and its #anchor (if any) to a heading of that file (GitHub's
#     slugs: lower case, punctuation dropped, spaces to hyphens).
#  2. Every command in a fenced block that names one of our programs
#     (build/<tree>/.../<program>, or skyshell-* / sky_*_bench at the start
#     of a line) names a program this build has, and each --option it passes
#     is in that program's --help. deploy/ scripts: each option is in the
#     script's text (their --help would start installing).
#  3. Every `--option` written as code anywhere in the pages (tables and
#     prose) is in one of our programs' --help or deploy/ scripts.
# Usage: check_docs.sh REPO_ROOT BUILD_DIR
set -u
root=${1:?usage: check_docs.sh REPO_ROOT BUILD_DIR}
build=${2:?usage: check_docs.sh REPO_ROOT BUILD_DIR}
status=0
fails=0
fail() { echo "FAIL: $1"; status=1; fails=$((fails + 1)); }

pages=("$root/README.md" "$root/server/API.md")
for f in "$root"/docs/*.md "$root"/docs/bench/*.md; do [ -f "$f" ] && pages+=("$f"); done

slug() {  # a heading's GitHub anchor
  printf '%s' "$1" | tr '[:upper:]' '[:lower:]' | sed -E 's/`//g; s/[^a-z0-9 _-]//g; s/ /-/g'
}
anchors_of() {  # every heading's slug in a markdown file, outside fenced blocks
  awk '/^```/ { fence = !fence; next } !fence && /^#+ / { sub(/^#+ +/, ""); print }' "$1" |
    while IFS= read -r h; do slug "$h"; echo; done
}

# 1. Links.
links=0
for page in "${pages[@]}"; do
  dir=$(dirname "$page")
  while IFS= read -r target; do
    links=$((links + 1))
    path=${target%%#*}
    anchor=""
    [[ "$target" == *"#"* ]] && anchor=${target#*#}
    if [ -z "$path" ]; then file=$page; else file="$dir/$path"; fi
    if [ ! -e "$file" ]; then
      hint=""
      case "$path" in contact/*|plots/*) hint=" (a bench table's link into its OUT directory: write the path as code)" ;; esac
      fail "${page#$root/}: link '$target': no file ${file#$root/}$hint"
      continue
    fi
    if [ -n "$anchor" ] && [ -f "$file" ] && [[ "$file" == *.md ]]; then
      anchors_of "$file" | grep -qxF -- "$anchor" || fail "${page#$root/}: link '$target': no heading with that anchor"
    fi
  done < <(awk '/^```/ { fence = !fence; next } !fence' "$page" |
    grep -oE '\]\([^) ]+\)' | sed -E 's/^\]\(//; s/\)$//' | grep -vE '^(https?|mailto):')
done

# Our programs, as this build has them.
# The shallowest path wins (a test's installed copy is deeper than the
# build's own program).
declare -A programs
while IFS= read -r p; do
  n=$(basename "$p")
  [ -n "${programs[$n]+x}" ] || programs[$n]=$p
done < <(find "$build" -type f -perm -u+x \( -name 'skyshell-*' -o -name 'sky_*_bench' \) \
  -not -path '*/CMakeFiles/*' 2>/dev/null | awk -F/ '{ print NF "\t" $0 }' | sort -n | cut -f2-)
# Programs whose --help is not an option list: their options are checked
# against their source instead.
declare -A sources=([sky_render_bench]="$root/tests/bench/render_bench.cpp")
declare -A helps
help_of() {
  local name=$1
  if [ -z "${helps[$name]+x}" ]; then
    if [ -n "${sources[$name]+x}" ]; then
      helps[$name]=$(cat "${sources[$name]}")
    else
      helps[$name]=$(timeout 20 "${programs[$name]}" --help 2>&1 </dev/null)
    fi
  fi
  printf '%s' "${helps[$name]}"
}

# 2. Commands in fenced blocks (a trailing backslash continues a line).
commands=0
for page in "${pages[@]}"; do
  while IFS= read -r line; do
    line=${line#\$ }
    first=${line%% *}
    name=$(basename "$first")
    case "$first" in
      build/*/*|skyshell-*|sky_*_bench|sky_weatherd_bench) ;;
      deploy/*)
        [ -f "$root/$first" ] || { fail "${page#$root/}: '$first' does not exist"; continue; }
        commands=$((commands + 1))
        for opt in $(printf '%s\n' "$line" | grep -oE '(^| )--[a-z0-9][a-z0-9-]*' | tr -d ' '); do
          grep -qF -- "$opt" "$root/$first" || fail "${page#$root/}: $first has no option $opt"
        done
        continue ;;
      *) continue ;;
    esac
    case "$name" in skyshell-*|sky_*) ;; *) continue ;; esac
    commands=$((commands + 1))
    if [ -z "${programs[$name]+x}" ]; then
      fail "${page#$root/}: '$name' is not a program this build has ($build)"
      continue
    fi
    help=$(help_of "$name")
    for opt in $(printf '%s\n' "$line" | grep -oE '(^| )--[a-z0-9][a-z0-9-]*' | tr -d ' '); do
      [ "$opt" = "--help" ] && continue
      grep -qE -- "(^|[^a-z0-9-])$opt([^a-z0-9-]|$)" <<<"$help" || fail "${page#$root/}: $name has no option $opt (its --help)"
    done
  done < <(awk '
    /^```/ { fence = !fence; cont = ""; next }
    !fence { next }
    { line = cont $0; sub(/^[ \t]+/, "", line) }
    /\\$/ { sub(/\\$/, "", line); cont = line " "; next }
    { cont = ""; print line }' "$page")
done

# 3. Options written as code: each is one of ours.
all_help=""
for name in "${!programs[@]}"; do all_help+=$(help_of "$name")$'\n'; done
# deploy/ scripts' own options, and the options deploy/flightgear passes
# to FlightGear (which the docs name when they explain it).
for s in "$root"/deploy/demo "$root"/deploy/test "$root"/deploy/setup "$root"/deploy/flightgear "$root"/deploy/bench/sweeps \
  "$root"/deploy/bench/transport-delay; do all_help+=$(cat "$s")$'\n'; done
# Other programs' options the docs quote, each with its program.
all_help+=" --generic "$'\n'  # FlightGear's fgfs: its ForeFlight output (docs/integrating.md)
rows=0
for page in "${pages[@]}"; do
  while IFS= read -r opt; do
    rows=$((rows + 1))
    grep -qE -- "(^|[^a-z0-9-])$opt([^a-z0-9-]|$)" <<<"$all_help" ||
      fail "${page#$root/}: option $opt is in no program's --help"
  done < <(grep -oE '`--[a-z0-9][a-z0-9-]*' "$page" | grep -oE -- '--[a-z0-9-]+' | sort -u)
done

echo "docs: ${#pages[@]} pages, $links relative links, $commands commands of ours in fenced blocks, $rows options written as code, ${#programs[@]} programs found; $fails problems"
exit $status
