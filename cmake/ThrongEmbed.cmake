# throng_embed(target SYMBOL sym DIR dir [PATTERN glob]): compiles every
# dir/<glob> (default *.yaml) into `target` as the io::EmbeddedSet `sym`
# (io/embedded.h), named by file stem. The one mechanism for data the
# executable carries, so the files stay the one source of truth: editing
# examples/circle.yaml changes `throng run circle`.
set(THRONG_EMBED_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/ThrongEmbedScript.cmake)

function(throng_embed target)
  cmake_parse_arguments(E "" "SYMBOL;DIR;PATTERN" "" ${ARGN})
  if(NOT E_SYMBOL OR NOT E_DIR)
    message(FATAL_ERROR "throng_embed: SYMBOL and DIR are required")
  endif()
  if(NOT E_PATTERN)
    set(E_PATTERN "*.yaml")
  endif()
  file(GLOB files CONFIGURE_DEPENDS ${E_DIR}/${E_PATTERN})
  list(SORT files)
  set(out ${CMAKE_CURRENT_BINARY_DIR}/generated/embedded_${E_SYMBOL}.cpp)
  add_custom_command(
    OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -DINPUT_DIR=${E_DIR} -DPATTERN=${E_PATTERN} -DSYMBOL=${E_SYMBOL} -DOUTPUT=${out} -P ${THRONG_EMBED_SCRIPT}
    DEPENDS ${files} ${THRONG_EMBED_SCRIPT}
    COMMENT "Embedding ${E_DIR}/${E_PATTERN} as ${E_SYMBOL}"
    VERBATIM)
  target_sources(${target} PRIVATE ${out})
endfunction()
