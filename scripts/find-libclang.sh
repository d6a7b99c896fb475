#!/usr/bin/env bash
# Print the path of a libclang that bindgen (fmi-sys' build script) can load, or exit 1.
#
# bindgen loads libclang's C API (clang_createIndex, …) through clang-sys, which looks for
# files named libclang.so, libclang-<v>.so, libclang.so.<v> or libclang-<v>.so.<v> in
# LIBCLANG_PATH, the loader's directories and /usr/lib*/llvm-*/lib. A name match is not
# enough: Debian's libclang-cpp<v> (shipped by the base image) is the C++ library, named
# libclang-cpp.so.<v>, without the C API. So every candidate must also export
# clang_createIndex. Override the searched directories with FIND_LIBCLANG_DIRS
# (colon-separated) and the symbol lister with FIND_LIBCLANG_NM (a command line; both
# used by the test suite).
set -uo pipefail

read -r -a nm <<<"${FIND_LIBCLANG_NM:-nm}"

# Whether library $1 exports clang_createIndex. nm's whole listing is read before it is
# searched: piping it into `grep -q` under pipefail lost the race whenever grep exited at
# the match while nm was still writing (nm killed by SIGPIPE, the pipeline "failed").
exports_c_api() {
    local symbols
    symbols=$("${nm[@]}" -D --defined-only "$1" 2>/dev/null) || return 1
    grep -qw clang_createIndex <<<"$symbols"
}

dirs=()
if [ -n "${FIND_LIBCLANG_DIRS:-}" ]; then
    IFS=: read -r -a dirs <<<"$FIND_LIBCLANG_DIRS"
else
    [ -n "${LIBCLANG_PATH:-}" ] && dirs+=("$LIBCLANG_PATH")
    while read -r d; do dirs+=("$d"); done < <(ldconfig -p 2>/dev/null | awk -F'=> ' 'NF==2{print $2}' | xargs -r -n1 dirname | sort -u)
    for d in /usr/lib/llvm-*/lib /usr/lib64/llvm-*/lib /usr/local/lib /usr/lib /usr/lib64 /usr/lib/x86_64-linux-gnu; do
        [ -d "$d" ] && dirs+=("$d")
    done
fi

for d in "${dirs[@]}"; do
    for f in "$d"/libclang.so "$d"/libclang-*.so "$d"/libclang.so.* "$d"/libclang-*.so.*; do
        [ -e "$f" ] || continue
        if exports_c_api "$f"; then
            echo "$f"
            exit 0
        fi
    done
done
exit 1
