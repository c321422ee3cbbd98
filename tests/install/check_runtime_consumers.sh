#!/bin/sh
# Builds and runs the runtime-only consumers against an installed kdm at PREFIX, in WORK: through
# find_package(kdm COMPONENTS runtime) and through pkg-config, C and C++ (-fno-exceptions -fno-rtti), also
# linked fully static where the runtime is static, and a project of C alone (which, where the command line
# is installed, embeds a set it bakes).
# Usage: check_runtime_consumers.sh PREFIX WORK
set -eu
prefix=$1 work=$2 here=$(cd "$(dirname "$0")" && pwd)
tiles="$here/../../tilesets/default.kdmt"  # loaded through allocator hooks that refuse
rm -rf "$work" && mkdir -p "$work"
cmake -S "$here/runtime_consumer" -B "$work/cmake" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/cmake" >/dev/null
"$work/cmake/runtime_c" "$tiles"
"$work/cmake/runtime_cpp"
# A static runtime links into a fully static program through CMake too (with zstd's static library).
if [ -n "$(find "$prefix" -name libkdm_runtime.a)" ]; then
  cmake -S "$here/runtime_consumer" -B "$work/cmake_static" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_EXE_LINKER_FLAGS=-static >/dev/null
  cmake --build "$work/cmake_static" >/dev/null
  "$work/cmake_static/runtime_c" "$tiles"
  "$work/cmake_static/runtime_cpp"
fi
if grep -F -q 'LINK_ONLY:>' "$(find "$prefix" -name kdmRuntimeTargets.cmake)"; then
  echo "kdm::runtime's exported link interface has an empty entry"; exit 1
fi
cmake -S "$here/runtime_c_consumer" -B "$work/cmake_c" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/cmake_c" >/dev/null
"$work/cmake_c/runtime_c_only"
if [ -x "$prefix/bin/kdm" ]; then  # a prefix with the command line
  "$work/cmake_c/embedded_c_only"
  # A program that never asks for the built-in set does not carry its 14 MB from the static library.
  if [ -n "$(find "$prefix" -name libkdm_runtime.a)" ] && nm "$work/cmake_c/embedded_c_only" | grep -q kdm_builtin_tileset; then
    echo "a program without the built-in set carries it"; exit 1
  fi
fi
pc_dir=$(dirname "$(find "$prefix" -name kdm-runtime.pc | head -n 1)")
flags=$(PKG_CONFIG_PATH="$pc_dir" pkg-config --cflags --libs kdm-runtime)
# shellcheck disable=SC2086  # the flags are words
cc -o "$work/pc_c" "$here/runtime_consumer/main.c" $flags
# shellcheck disable=SC2086
c++ -std=c++17 -fno-exceptions -fno-rtti -o "$work/pc_cpp" "$here/runtime_consumer/main.cpp" $flags
libdir=$(PKG_CONFIG_PATH="$pc_dir" pkg-config --variable=libdir kdm-runtime)
LD_LIBRARY_PATH="$libdir" "$work/pc_c" "$tiles"
LD_LIBRARY_PATH="$libdir" "$work/pc_cpp"
# A component kdm does not have is named in the refusal.
mkdir -p "$work/bogus"
printf 'cmake_minimum_required(VERSION 3.20)\nproject(bogus LANGUAGES C)\nfind_package(kdm REQUIRED COMPONENTS bogus)\n' \
  >"$work/bogus/CMakeLists.txt"
if cmake -S "$work/bogus" -B "$work/bogus/build" -DCMAKE_PREFIX_PATH="$prefix" >"$work/bogus.log" 2>&1; then
  echo "an unknown component was found"; exit 1
fi
grep -q "no component 'bogus'" "$work/bogus.log" || { echo "the unknown component was not named:"; cat "$work/bogus.log"; exit 1; }
echo "runtime consumers ok"
