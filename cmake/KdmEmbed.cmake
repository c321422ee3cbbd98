# kdm_embed_file(INPUT OUTPUT SYMBOL): writes OUTPUT, a C++ source defining
#   extern const unsigned char SYMBOL[]; extern const std::size_t SYMBOL_size;
# with the bytes of INPUT. Runs at configure time and again whenever INPUT changes.
# As a script, it does the same at build time (kdm_bake_tileset's EMBED):
#   cmake -DKDM_EMBED_INPUT=... -DKDM_EMBED_OUTPUT=... -DKDM_EMBED_SYMBOL=... -P KdmEmbed.cmake
if(CMAKE_SCRIPT_MODE_FILE)
  cmake_minimum_required(VERSION 3.20)  # a script has no project to set its policies
endif()

# Rewrites OUTPUT only where its bytes change (at configure time, so that an unchanged set is not compiled
# again), unless ALWAYS is given (at build time, where OUTPUT must end newer than INPUT). C_LINKAGE gives
# the symbols C linkage and writes a source that is C and C++ alike, for projects of either language.
function(kdm_write_embedded_source input output symbol)
  file(READ ${input} hex HEX)
  string(LENGTH "${hex}" hex_length)
  math(EXPR size "${hex_length} / 2")
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
  string(REGEX REPLACE "((0x..,){32})" "\\1\n" bytes "${bytes}")
  if("C_LINKAGE" IN_LIST ARGN)
    string(CONCAT head
      "#include <stddef.h>\n"
      "#ifdef __cplusplus\n#define KDM_EMBED_ALIGNED alignas(16)\nextern \"C\" {\n"
      "#elif defined(__STDC_VERSION__) && __STDC_VERSION__ >= 201112L\n#define KDM_EMBED_ALIGNED _Alignas(16)\n"
      "#else\n#define KDM_EMBED_ALIGNED\n#endif\n"
      "extern const unsigned char ${symbol}[];\nextern const size_t ${symbol}_size;\n"
      "#ifdef __cplusplus\n}\n#endif\n"
      "KDM_EMBED_ALIGNED const unsigned char ${symbol}[] = {\n")
    set(size_type "size_t")
  else()
    string(CONCAT head
      "#include <cstddef>\n"
      "extern const unsigned char ${symbol}[];\nextern const std::size_t ${symbol}_size;\n"
      "alignas(16) const unsigned char ${symbol}[] = {\n")
    set(size_type "std::size_t")
  endif()
  string(REPLACE "*/" "* /" named "${input}")  # a path cannot end the comment early
  file(WRITE ${output}.tmp
    "/* Generated from ${named} by cmake/KdmEmbed.cmake. Do not edit. */\n" "${head}" "${bytes}\n};\n"
    "const ${size_type} ${symbol}_size = ${size};\n")
  if("ALWAYS" IN_LIST ARGN)
    file(RENAME ${output}.tmp ${output})
  else()  # copy_if_different, not file(COPY_FILE), which needs CMake 3.21
    execute_process(COMMAND "${CMAKE_COMMAND}" -E copy_if_different ${output}.tmp ${output} RESULT_VARIABLE result)
    if(NOT result EQUAL 0)
      message(FATAL_ERROR "kdm_embed_file: could not write ${output}")
    endif()
    file(REMOVE ${output}.tmp)
  endif()
endfunction()

function(kdm_embed_file input output symbol)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${input})
  kdm_write_embedded_source(${input} ${output} ${symbol})
endfunction()

if(CMAKE_SCRIPT_MODE_FILE AND DEFINED KDM_EMBED_INPUT)
  kdm_write_embedded_source("${KDM_EMBED_INPUT}" "${KDM_EMBED_OUTPUT}" "${KDM_EMBED_SYMBOL}" ALWAYS C_LINKAGE)
endif()
