# kdm_bake_tileset(OUTPUT <file> RECIPE <file> [TARGET <name>] [EMBED <name>] [THREADS <n>] [VERIFY]
#                  [VERIFY_ARGS <kdm verify option>...])
#
# Adds a build step that bakes the tile set OUTPUT from RECIPE with the kdm command line (kdm::kdm), and
# bakes it again whenever the recipe or kdm changes.
#   OUTPUT   the tile-set file to write; a relative path is taken from the current binary directory.
#   RECIPE   the recipe file; a relative path is taken from the current source directory.
#   TARGET   the custom target, built by default, that bakes OUTPUT. It alone runs the bake: a target that
#            reads OUTPUT depends on it (add_dependencies(<target> TARGET), or TARGET beside OUTPUT in a
#            custom command's DEPENDS). Naming OUTPUT among the sources of targets that do not depend on it
#            lets a Makefile build run the bake in each at once, into the same file. Without TARGET an
#            internal target, built by default, bakes it.
#   EMBED    a static library of that name holding the set's bytes, for a program that carries its set
#            inside it: link it, `#include "<name>.h"` and pass `<name>, <name>_size` to
#            kdm::Tileset::load_memory (or kdm_tileset_load_memory). The name must be a C identifier, and
#            not a C or C++ keyword. The library depends on the target that bakes OUTPUT.
#            Compiling the bytes as an array costs the compiler time and memory: for a set the size of the
#            built-in one (14 MB), a 71 MB source, 24 s and 2.4 GB in g++; load such a set from its file.
#   THREADS  baking and verifying threads (0, the default, takes every core). The file does not depend on it.
#   VERIFY   also runs `kdm verify` (the generator test) on the baked file, and fails the build if any
#            check fails.
#   VERIFY_ARGS  more `kdm verify` options (needs VERIFY), e.g. the design's bars for holes, which verify
#            only reports by default: VERIFY_ARGS --hole-largest 1.0 --holes-per-1e5 10.
# The bake writes a scratch file beside OUTPUT and renames it into place only once every step has passed,
# and only if its bytes differ from OUTPUT's: a failed or interrupted step leaves OUTPUT as it was and the
# next build tries again, and a bake that gives the same set (a touched recipe, a new comment) leaves OUTPUT
# untouched, so that nothing built from it (EMBED's library, its users) is built again.
function(kdm_bake_tileset)
  cmake_parse_arguments(PARSE_ARGV 0 arg "VERIFY" "OUTPUT;RECIPE;TARGET;EMBED;THREADS" "VERIFY_ARGS")
  if(arg_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "kdm_bake_tileset: unknown argument(s) ${arg_UNPARSED_ARGUMENTS}")
  endif()
  if(arg_KEYWORDS_MISSING_VALUES)  # THREADS with no count would otherwise take every core, silently
    message(FATAL_ERROR "kdm_bake_tileset: ${arg_KEYWORDS_MISSING_VALUES} given without a value")
  endif()
  if(arg_VERIFY_ARGS AND NOT arg_VERIFY)
    message(FATAL_ERROR "kdm_bake_tileset: VERIFY_ARGS needs VERIFY")
  endif()
  if(arg_VERIFY_ARGS MATCHES "\\|")
    message(FATAL_ERROR "kdm_bake_tileset: VERIFY_ARGS may not hold '|'")
  endif()
  foreach(required OUTPUT RECIPE)
    if(NOT arg_${required})
      message(FATAL_ERROR "kdm_bake_tileset: ${required} is required")
    endif()
  endforeach()
  if(NOT DEFINED arg_THREADS)
    set(arg_THREADS 0)
  elseif(NOT arg_THREADS MATCHES "^[0-9]+$")
    message(FATAL_ERROR "kdm_bake_tileset: THREADS must be a count (0 for every core), not '${arg_THREADS}'")
  endif()
  if(NOT TARGET kdm::kdm)
    message(FATAL_ERROR "kdm_bake_tileset: the kdm command line (kdm::kdm) is not there; build kdm with "
                        "KDM_BUILD_TOOLS=ON, or install it with its tools")
  endif()
  foreach(name TARGET EMBED)
    if(arg_${name} AND TARGET ${arg_${name}})
      message(FATAL_ERROR "kdm_bake_tileset: ${name} '${arg_${name}}' already exists")
    endif()
  endforeach()
  if(arg_EMBED AND NOT arg_EMBED MATCHES "^[A-Za-z_][A-Za-z0-9_]*$")
    message(FATAL_ERROR "kdm_bake_tileset: EMBED '${arg_EMBED}' is not a C identifier")
  endif()
  # Keywords of C (to C23) and C++ (to C++20) look like identifiers but cannot name the array.
  set(keywords
      _Alignas _Alignof _Atomic _BitInt _Bool _Complex _Decimal128 _Decimal32 _Decimal64 _Generic _Imaginary
      _Noreturn _Static_assert _Thread_local alignas alignof and and_eq asm auto bitand bitor bool break case
      catch char char16_t char32_t char8_t class co_await co_return co_yield compl concept const const_cast
      consteval constexpr constinit continue decltype default delete do double dynamic_cast else enum
      explicit export extern false float for friend goto if inline int long mutable namespace new noexcept
      not not_eq nullptr operator or or_eq private protected public register reinterpret_cast requires
      restrict return short signed sizeof static static_assert static_cast struct switch template this
      thread_local throw true try typedef typeid typename typeof typeof_unqual union unsigned using virtual
      void volatile wchar_t while xor xor_eq)
  if(arg_EMBED IN_LIST keywords)
    message(FATAL_ERROR "kdm_bake_tileset: EMBED '${arg_EMBED}' is a C or C++ keyword, which cannot name "
                        "the embedded array; choose another name")
  endif()

  get_filename_component(recipe "${arg_RECIPE}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  get_filename_component(output "${arg_OUTPUT}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_BINARY_DIR}")
  if(NOT EXISTS "${recipe}" OR IS_DIRECTORY "${recipe}")
    message(FATAL_ERROR "kdm_bake_tileset: RECIPE '${recipe}' is not a file")
  endif()
  # One target owns each bake (CMake's rule for a custom command's output): two would run it at once.
  get_property(baked GLOBAL PROPERTY KDM_BAKED_TILESETS)
  if(output IN_LIST baked)
    message(FATAL_ERROR "kdm_bake_tileset: OUTPUT '${output}' is baked by another kdm_bake_tileset already")
  endif()
  set_property(GLOBAL APPEND PROPERTY KDM_BAKED_TILESETS "${output}")
  if(arg_TARGET)
    set(owner ${arg_TARGET})
  else()
    file(RELATIVE_PATH owner "${CMAKE_BINARY_DIR}" "${output}")
    string(MAKE_C_IDENTIFIER "kdm_bake_${owner}" owner)
  endif()
  get_filename_component(output_dir "${output}" DIRECTORY)
  set(scratch "${output}.baking.kdmt")  # a tile set's extension, of which kdm bake does not warn
  # The bake's own output is a stamp, OUTPUT its byproduct: a bake that gives the same bytes leaves OUTPUT,
  # and its time, as they were (KdmBakeStep.cmake), and Ninja and Make then rebuild nothing from it.
  set(stamp "${CMAKE_CURRENT_BINARY_DIR}/kdm_baked/${owner}.stamp")
  set(step_args "-DKDM_BAKE_SCRATCH=${scratch}" "-DKDM_BAKE_OUTPUT=${output}" "-DKDM_BAKE_STAMP=${stamp}")
  if(arg_VERIFY)
    list(JOIN arg_VERIFY_ARGS "|" verify_args)  # one word through the command line: '|' for ';'
    list(APPEND step_args "-DKDM_VERIFY_KDM=$<TARGET_FILE:kdm::kdm>" "-DKDM_VERIFY_THREADS=${arg_THREADS}"
                          "-DKDM_VERIFY_ARGS=${verify_args}")
  endif()
  set(depends "${recipe}" "$<TARGET_FILE:kdm::kdm>" "${CMAKE_CURRENT_FUNCTION_LIST_DIR}/KdmBakeStep.cmake")
  if(CMAKE_GENERATOR MATCHES "Make")
    # Make knows no rule for a byproduct: this one makes a missing OUTPUT look new, so the stamp, which
    # depends on it, is remade and OUTPUT baked again (Ninja does so for a missing byproduct itself).
    add_custom_command(OUTPUT "${output}" COMMAND "${CMAKE_COMMAND}" -E true VERBATIM)
    list(APPEND depends "${output}")
  endif()
  add_custom_command(OUTPUT "${stamp}" BYPRODUCTS "${output}"
                     COMMAND "${CMAKE_COMMAND}" -E make_directory "${output_dir}" "${CMAKE_CURRENT_BINARY_DIR}/kdm_baked"
                     COMMAND kdm::kdm bake "${recipe}" -o "${scratch}" --threads ${arg_THREADS}
                     COMMAND "${CMAKE_COMMAND}" ${step_args} -P "${CMAKE_CURRENT_FUNCTION_LIST_DIR}/KdmBakeStep.cmake"
                     DEPENDS ${depends}
                     COMMENT "Baking tile set ${output} from ${recipe}"
                     VERBATIM)
  add_custom_target(${owner} ALL DEPENDS "${stamp}")
  if(arg_EMBED)
    set(include_dir "${CMAKE_CURRENT_BINARY_DIR}/kdm_embedded/${arg_EMBED}")
    # C89 comments only: a C90 project includes the header too. A path cannot end the comment early.
    string(REPLACE "*/" "* /" named "${output}, baked from ${recipe}")
    string(CONCAT header
      "/* The bytes of ${named} (kdm_bake_tileset). Generated: do not edit. */\n"
      "#pragma once\n#include <stddef.h>\n"
      "#ifdef __cplusplus\nextern \"C\" {\n#endif\n"
      "extern const unsigned char ${arg_EMBED}[];\nextern const size_t ${arg_EMBED}_size;\n"
      "#ifdef __cplusplus\n}\n#endif\n")
    set(old_header "")
    if(EXISTS "${include_dir}/${arg_EMBED}.h")
      file(READ "${include_dir}/${arg_EMBED}.h" old_header)
    endif()
    if(NOT old_header STREQUAL header)  # written only where it changes: its includers are not rebuilt
      file(WRITE "${include_dir}/${arg_EMBED}.h" "${header}")
    endif()
    # The source is C and C++ alike: compiled as C++ where the project has it, else as C.
    get_property(languages GLOBAL PROPERTY ENABLED_LANGUAGES)
    if("CXX" IN_LIST languages)
      set(extension cpp)
    elseif("C" IN_LIST languages)
      set(extension c)
    else()
      message(FATAL_ERROR "kdm_bake_tileset: EMBED compiles a C or C++ source; enable C or CXX in project()")
    endif()
    set(source "${CMAKE_CURRENT_BINARY_DIR}/kdm_embedded/${arg_EMBED}.${extension}")
    add_custom_command(OUTPUT "${source}"
                       COMMAND "${CMAKE_COMMAND}" "-DKDM_EMBED_INPUT=${output}" "-DKDM_EMBED_OUTPUT=${source}"
                               "-DKDM_EMBED_SYMBOL=${arg_EMBED}" -P "${CMAKE_CURRENT_FUNCTION_LIST_DIR}/KdmEmbed.cmake"
                       DEPENDS "${output}" "${CMAKE_CURRENT_FUNCTION_LIST_DIR}/KdmEmbed.cmake"
                       COMMENT "Embedding tile set ${output} as ${arg_EMBED}"
                       VERBATIM)
    add_library(${arg_EMBED} STATIC "${source}")
    add_dependencies(${arg_EMBED} ${owner})  # so that its own copy of the bake's rule finds OUTPUT made
    target_include_directories(${arg_EMBED} PUBLIC "$<BUILD_INTERFACE:${include_dir}>")
  endif()
endfunction()
