# throng_embed_scenarios(target dir): compiles every dir/*.yaml into `target`
# as the built-in scenarios (io/scenario_yaml.h), so the examples are the one
# source of truth: editing examples/circle.yaml changes `throng run circle`.
set(THRONG_EMBED_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/ThrongEmbedScript.cmake)

function(throng_embed_scenarios target dir)
  file(GLOB files CONFIGURE_DEPENDS ${dir}/*.yaml)
  list(SORT files)
  set(out ${CMAKE_CURRENT_BINARY_DIR}/generated/builtin_scenarios.cpp)
  add_custom_command(
    OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -DINPUT_DIR=${dir} -DOUTPUT=${out} -P ${THRONG_EMBED_SCRIPT}
    DEPENDS ${files} ${THRONG_EMBED_SCRIPT}
    COMMENT "Embedding the built-in scenarios from ${dir}"
    VERBATIM)
  target_sources(${target} PRIVATE ${out})
endfunction()
