# cmake -DINPUT_DIR=dir -DPATTERN=*.yaml -DSYMBOL=name -DOUTPUT=file.cpp -P ThrongEmbedScript.cmake
# Writes every INPUT_DIR/PATTERN as a byte array (any content is safe) and an
# io::EmbeddedSet SYMBOL listing them by file stem.
file(GLOB files ${INPUT_DIR}/${PATTERN})
list(SORT files)
set(body "")
set(table "")
set(index 0)
foreach(f ${files})
  get_filename_component(name ${f} NAME_WE)
  file(READ ${f} hex HEX)
  string(LENGTH "${hex}" hex_length)
  math(EXPR size "${hex_length} / 2")
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
  string(REGEX REPLACE "(0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,)" "\\1\n" bytes "${bytes}")
  string(APPEND body "const char kFile${index}[] = {\n${bytes}0};\n")
  string(APPEND table "    {\"${name}\", kFile${index}, ${size}},\n")
  math(EXPR index "${index} + 1")
endforeach()
if(index EQUAL 0)
  string(APPEND table "    {\"\", \"\", 0},\n")
endif()
file(WRITE ${OUTPUT}.tmp "// Generated from ${INPUT_DIR}/${PATTERN} by cmake/ThrongEmbedScript.cmake: do not edit.
#include \"io/embedded.h\"

namespace throng::io {
namespace {
${body}const EmbeddedFile kFiles[] = {
${table}};
}  // namespace
extern const EmbeddedSet ${SYMBOL};
const EmbeddedSet ${SYMBOL}{kFiles, ${index}};
}  // namespace throng::io
")
file(COPY_FILE ${OUTPUT}.tmp ${OUTPUT} ONLY_IF_DIFFERENT)
file(REMOVE ${OUTPUT}.tmp)
