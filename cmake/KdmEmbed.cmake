# kdm_embed_file(INPUT OUTPUT SYMBOL): writes OUTPUT, a C++ source defining
#   extern const unsigned char SYMBOL[]; extern const std::size_t SYMBOL_size;
# with the bytes of INPUT. Runs at configure time and again whenever INPUT changes.
function(kdm_embed_file input output symbol)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${input})
  file(READ ${input} hex HEX)
  string(LENGTH "${hex}" hex_length)
  math(EXPR size "${hex_length} / 2")
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
  string(REGEX REPLACE "((0x..,){32})" "\\1\n" bytes "${bytes}")
  file(WRITE ${output}.tmp
    "// Generated from ${input} by cmake/KdmEmbed.cmake. Do not edit.\n"
    "#include <cstddef>\n"
    "extern const unsigned char ${symbol}[];\nextern const std::size_t ${symbol}_size;\n"
    "alignas(16) const unsigned char ${symbol}[] = {\n${bytes}\n};\n"
    "const std::size_t ${symbol}_size = ${size};\n")
  file(COPY_FILE ${output}.tmp ${output} ONLY_IF_DIFFERENT)
endfunction()
