#!/usr/bin/env bash
# Architecture rule from DESIGN.md / STYLE.md: server/ and renderer/ never
# include each other (they meet only in protocol/), the renderer does not use
# sim_clients/, and protocol/ stays pure
# (no sockets, threads, files, GPU or logging). Fails on the first hit.
set -u
root=${1:?usage: check_layering.sh REPO_ROOT}
status=0
hit() { echo "FAIL: $1"; echo "$2"; status=1; }

out=$(grep -rnE '#include *["<](sky/(app|render|server)/|(\.\./)*(renderer|server)/)' "$root/server" 2>/dev/null | grep -E 'sky/(app|render)/|renderer/')
[ -z "$out" ] || hit "server/ includes renderer code" "$out"
out=$(grep -rnE '#include *["<](sky/server/|(\.\./)*server/)' "$root/renderer" 2>/dev/null)
[ -z "$out" ] || hit "renderer/ includes server code" "$out"
out=$(grep -rnE '#include *<(boost/asio|sys/socket\.h|thread|fstream|vulkan/|spdlog/|sqlite3\.h)' "$root/protocol" 2>/dev/null)
[ -z "$out" ] || hit "protocol/ is not pure (sockets, threads, files, GPU or logging)" "$out"
out=$(grep -rnE 'sky_server|sky_render' "$root/server/CMakeLists.txt" "$root/renderer" --include=CMakeLists.txt 2>/dev/null | grep -E 'server/CMakeLists.txt:.*sky_render|renderer/.*sky_server')
[ -z "$out" ] || hit "server and renderer targets link each other" "$out"
out=$(grep -rnE '#include *["<](sky/sim/|(\.\./)*sim_clients/)' "$root/renderer" 2>/dev/null)
[ -z "$out" ] || hit "renderer/ includes sim_clients/ code (flight files are read through protocol/)" "$out"
out=$(grep -rnE '\bsky_sim\b' "$root/renderer" --include=CMakeLists.txt 2>/dev/null)
[ -z "$out" ] || hit "renderer targets link sim_clients/" "$out"
# Every edge of docs/architecture.md ("Folders and what each may depend
# on"): a folder includes (sky/<module>/...) and links (CMake sky_* targets)
# only itself and the folders listed for it; every other edge is forbidden.
owner_of_module() {
  case $1 in
    core|geo|config|weather|stream|cigi|fgfdm|foreflight|flight) echo protocol ;;
    render) echo renderer/core ;;
    app) echo renderer/app ;;
    bench) echo renderer/bench ;;
    server) echo server ;;
    sim) echo sim_clients ;;
    *) echo "" ;;
  esac
}
owner_of_target() {
  case $1 in
    sky_core|sky_geo|sky_config|sky_protocol) echo protocol ;;
    sky_shader_headers|sky_shaders) echo shaders ;;
    sky_server) echo server ;;
    sky_render_core) echo renderer/core ;;
    sky_render_app) echo renderer/app ;;
    sky_bench_metrics|sky_bench_suite|sky_bench_run) echo renderer/bench ;;
    sky_sim) echo sim_clients ;;
    *) echo "" ;;
  esac
}
allowed_edges() {
  case $1 in
    protocol) echo "" ;;
    shaders) echo "protocol" ;;
    server) echo "protocol" ;;
    renderer/core) echo "protocol shaders" ;;
    renderer/app) echo "protocol renderer/core" ;;
    renderer/bench) echo "protocol renderer/core" ;;
    sim_clients) echo "protocol" ;;
  esac
}
edge_ok() {  # from to
  [ "$1" = "$2" ] && return 0
  for a in $(allowed_edges "$1"); do [ "$a" = "$2" ] && return 0; done
  return 1
}
for from in protocol shaders server renderer/core renderer/app renderer/bench sim_clients; do
  bad=""
  while IFS= read -r line; do
    [ -n "$line" ] || continue
    module=$(printf '%s' "$line" | sed -E 's|.*#include *["<]sky/([a-z_]+)/.*|\1|')
    to=$(owner_of_module "$module")
    [ -n "$to" ] && ! edge_ok "$from" "$to" && bad+="$line (-> $to)"$'\n'
  done < <(grep -rnE '#include *["<]sky/[a-z_]+/' "$root/$from" 2>/dev/null)
  while IFS= read -r line; do
    [ -n "$line" ] || continue
    target=${line##*:}
    to=$(owner_of_target "$target")
    [ -n "$to" ] && ! edge_ok "$from" "$to" && bad+="$line (-> $to)"$'\n'
  done < <(grep -rnoE '\bsky_[a-z_]+\b' "$root/$from" --include=CMakeLists.txt 2>/dev/null)
  [ -z "$bad" ] || hit "$from/ depends on a folder docs/architecture.md does not allow it" "$bad"
done
[ $status -eq 0 ] && echo "layering ok: every include and link follows docs/architecture.md's edges; server/ and renderer/ meet only in protocol/, protocol/ is pure"
exit $status
