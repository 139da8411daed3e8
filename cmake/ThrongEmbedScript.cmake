# cmake -DINPUT_DIR=examples -DOUTPUT=builtin_scenarios.cpp -P ThrongEmbedScript.cmake
# Writes every INPUT_DIR/*.yaml as a byte array (any content is safe).
file(GLOB files ${INPUT_DIR}/*.yaml)
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
file(WRITE ${OUTPUT}.tmp "// Generated from ${INPUT_DIR}/*.yaml by cmake/ThrongEmbedScript.cmake: do not edit.
#include <cstddef>

namespace throng::io::detail {
struct EmbeddedFile {
  const char* name;
  const char* text;
  std::size_t size;
};
namespace {
${body}}  // namespace
extern const EmbeddedFile kBuiltinScenarios[] = {
${table}};
extern const std::size_t kBuiltinScenarioCount = ${index};
}  // namespace throng::io::detail
")
file(COPY_FILE ${OUTPUT}.tmp ${OUTPUT} ONLY_IF_DIFFERENT)
file(REMOVE ${OUTPUT}.tmp)
