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
[ $status -eq 0 ] && echo "layering ok: server/ and renderer/ meet only in protocol/, protocol/ is pure"
exit $status
