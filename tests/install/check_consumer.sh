#!/bin/sh
# Builds and runs the find_package consumer (consumer/) against an installed kdm at PREFIX, in WORK, and
# checks its build-time bake (kdm_bake_tileset): a second build bakes nothing, a changed recipe is baked
# again, and a recipe that cannot be baked, or whose set fails verification, fails the build. Then each
# of the bake's patterns in a parallel Makefile build (embed_consumer/), and a bake by a project of no
# language through the tool component alone (tool_consumer/).
# Usage: check_consumer.sh PREFIX WORK
set -eu
prefix=$1 work=$2 here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work"
cp -R "$here/consumer" "$work/src"
cmake -S "$work/src" -B "$work/build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/build" >/dev/null
"$work/build/consumer"
baked=$work/build/tiles/small.kdmt
cp "$baked" "$work/first.kdmt"
cmake --build "$work/build" >"$work/again.log"
if grep -q "Baking tile set" "$work/again.log"; then echo "an unchanged recipe was baked again"; exit 1; fi
echo "seed 2" >>"$work/src/small.recipe"
cmake --build "$work/build" >"$work/changed.log"
grep -q "Baking tile set" "$work/changed.log" || { echo "a changed recipe was not baked again"; exit 1; }
if cmp -s "$baked" "$work/first.kdmt"; then echo "the recipe's new seed left the tile set as it was"; exit 1; fi
"$work/build/consumer" >"$work/changed.out" || { cat "$work/changed.out"; exit 1; }  # the embedded set follows
# VERIFY_ARGS reach kdm verify: a bar no set meets fails the build, and names the check.
sed 's/VERIFY)/VERIFY VERIFY_ARGS --hole-largest 0.01)/' "$here/consumer/CMakeLists.txt" >"$work/src/CMakeLists.txt"
touch "$work/src/small.recipe"  # Makefiles do not follow a custom command's own line
if cmake --build "$work/build" >"$work/strict.log" 2>&1; then echo "a set failing VERIFY_ARGS' bar was built"; exit 1; fi
grep -q "largest hole" "$work/strict.log" || { echo "VERIFY_ARGS' failure did not say why:"; cat "$work/strict.log"; exit 1; }
cp "$here/consumer/CMakeLists.txt" "$work/src/CMakeLists.txt"
# A recipe the baker refuses, and one too hot to pass the verification: each fails the build,
# and each time the next build tries again.
printf 'levels 0\n' >"$work/src/small.recipe"
if cmake --build "$work/build" >"$work/bad.log" 2>&1; then echo "a recipe with 0 levels was baked"; exit 1; fi
grep -q "levels" "$work/bad.log" || { echo "the refused bake did not say why:"; cat "$work/bad.log"; exit 1; }
printf 'colours 1\nlevels 2\nbase_points 32\ntemperature 50\n' >"$work/src/small.recipe"
if cmake --build "$work/build" >"$work/unverified.log" 2>&1; then echo "a set failing verification was built"; exit 1; fi
grep -q "failed [0-9]* check" "$work/unverified.log" || { echo "verification did not say why:"; cat "$work/unverified.log"; exit 1; }
if [ -e "$baked.baking.kdmt" ]; then echo "the failed verification left $baked.baking.kdmt behind"; exit 1; fi
if cmake --build "$work/build" >/dev/null 2>&1; then echo "the build after a failed verification passed"; exit 1; fi
# A project of C alone in each of kdm_bake_tileset's patterns, with Makefiles on two jobs: each set is
# baked once, by the one target that owns its bake, and each embedded set is its file's bytes.
mkdir -p "$work/embed"
cp -R "$here/embed_consumer" "$work/embed/src"
cp "$here/consumer/small.recipe" "$work/embed/src/"
cmake -S "$work/embed/src" -B "$work/embed/build" -G "Unix Makefiles" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/embed/build" -j2 >"$work/embed/build.log" 2>&1 || { cat "$work/embed/build.log"; exit 1; }
if grep "kdm bake: warning" "$work/embed/build.log"; then echo "the bake warned"; exit 1; fi
for set in a b c; do
  bakes=$(grep -c "Baking tile set .*/$set\.kdmt from" "$work/embed/build.log" || true)
  [ "$bakes" = 1 ] || { echo "$set.kdmt was baked $bakes times:"; cat "$work/embed/build.log"; exit 1; }
done
"$work/embed/build/embedded_a" >/dev/null
"$work/embed/build/embedded_b" >/dev/null
cmp "$work/embed/build/c.kdmt" "$work/embed/build/c_copy.kdmt"
# A touched recipe, and a new comment in it, bake the same bytes again: the set keeps its time, and
# nothing built from it is built again.
before=$(ls -l --time-style=full-iso "$work/embed/build/a.kdmt" "$work/embed/build/embedded_a")
for edit in "touch" "echo '# a comment' >>"; do
  eval "$edit \"\$work/embed/src/small.recipe\""
  cmake --build "$work/embed/build" -j2 >"$work/embed/again.log" 2>&1 || { cat "$work/embed/again.log"; exit 1; }
  grep -q "Baking tile set .*/a\.kdmt from" "$work/embed/again.log" || { echo "$edit: the recipe was not baked again"; exit 1; }
  if grep -q -e "Embedding" -e "Linking" "$work/embed/again.log"; then
    echo "$edit: the same set was embedded or linked again:"; cat "$work/embed/again.log"; exit 1
  fi
  [ "$(ls -l --time-style=full-iso "$work/embed/build/a.kdmt" "$work/embed/build/embedded_a")" = "$before" ] ||
    { echo "$edit: the same set, or its program, has a new time"; exit 1; }
done
# A removed set is baked again.
rm "$work/embed/build/a.kdmt"
cmake --build "$work/embed/build" -j2 >"$work/embed/removed.log" 2>&1 || { cat "$work/embed/removed.log"; exit 1; }
"$work/embed/build/embedded_a" >/dev/null
# A project of no language bakes through the tool component alone.
cmake -S "$here/tool_consumer" -B "$work/tool" -DCMAKE_PREFIX_PATH="$prefix" >"$work/tool.log" 2>&1 ||
  { cat "$work/tool.log"; exit 1; }
cmake --build "$work/tool" >/dev/null
[ -s "$work/tool/small.kdmt" ] || { echo "the tool component alone baked nothing"; exit 1; }
# A C or C++ keyword cannot name an embedded set: refused at configure time, by name.
for keyword in int class; do
  mkdir -p "$work/keyword_$keyword"
  cp "$here/consumer/small.recipe" "$work/keyword_$keyword/"
  printf '%s\n' 'cmake_minimum_required(VERSION 3.20)' 'project(keyword LANGUAGES C)' \
    'find_package(kdm 0.5 REQUIRED COMPONENTS tool)' \
    "kdm_bake_tileset(OUTPUT a.kdmt RECIPE small.recipe EMBED $keyword)" >"$work/keyword_$keyword/CMakeLists.txt"
  if cmake -S "$work/keyword_$keyword" -B "$work/keyword_$keyword/build" -DCMAKE_PREFIX_PATH="$prefix" \
    >"$work/keyword_$keyword.log" 2>&1; then
    echo "EMBED $keyword was configured"; exit 1
  fi
  tr -s ' \n' ' ' <"$work/keyword_$keyword.log" | grep -q "EMBED '$keyword' is a C or C++ keyword" ||
    { echo "EMBED $keyword was not refused by name:"; cat "$work/keyword_$keyword.log"; exit 1; }
done
# Two bakes of one file would race: the second is refused.
mkdir -p "$work/twice"
cp "$here/consumer/small.recipe" "$work/twice/"
printf '%s\n' 'cmake_minimum_required(VERSION 3.20)' 'project(twice LANGUAGES C)' \
  'find_package(kdm 0.5 REQUIRED COMPONENTS tool)' \
  'kdm_bake_tileset(OUTPUT a.kdmt RECIPE small.recipe TARGET first)' \
  'kdm_bake_tileset(OUTPUT a.kdmt RECIPE small.recipe TARGET second)' >"$work/twice/CMakeLists.txt"
if cmake -S "$work/twice" -B "$work/twice/build" -DCMAKE_PREFIX_PATH="$prefix" >"$work/twice.log" 2>&1; then
  echo "a second bake of one OUTPUT was configured"; exit 1
fi
tr -s ' \n' ' ' <"$work/twice.log" | grep -q "is baked by another kdm_bake_tileset" || { echo "the second bake was not named:"; cat "$work/twice.log"; exit 1; }
# The sampler through pkg-config, for C++ builds without CMake.
pc_dir=$(dirname "$(find "$prefix" -name kdm-generator.pc | head -n 1)")
cat >"$work/pc_generator.cpp" <<'CPP'
#include <cstdio>
#include <kdm/generator/sampler.h>
int main() {
  kdm::gen::SamplerOptions o;
  o.n = 100;
  std::printf("pkg-config sampler %zu points\n", kdm::gen::sample(o).size());
}
CPP
# shellcheck disable=SC2046  # the flags are words
c++ -std=c++17 -o "$work/pc_generator" "$work/pc_generator.cpp" $(PKG_CONFIG_PATH="$pc_dir" pkg-config --cflags --libs kdm-generator)
LD_LIBRARY_PATH="$(PKG_CONFIG_PATH="$pc_dir" pkg-config --variable=libdir kdm-generator)" "$work/pc_generator" |
  grep -q "pkg-config sampler 100 points" || { echo "the sampler through pkg-config did not run"; exit 1; }
echo "consumer ok"
