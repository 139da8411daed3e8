# Shared build settings for every throng target.

set(THRONG_WARNINGS -Wall -Wextra -Wpedantic -Wshadow -Wconversion-null -Wno-unused-parameter)
if(THRONG_WERROR)
  list(APPEND THRONG_WARNINGS -Werror)
endif()
set(THRONG_SANITIZER_FLAGS -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all)

# throng_setup_target(target): warnings, sanitizers and include path.
function(throng_setup_target target)
  target_compile_options(${target} PRIVATE $<$<COMPILE_LANGUAGE:CXX>:${THRONG_WARNINGS}>)
  if(THRONG_CUDA)
    target_compile_options(${target} PRIVATE
      $<$<COMPILE_LANGUAGE:CUDA>:--extended-lambda --expt-relaxed-constexpr -Xcompiler=-Wall>)
  endif()
  if(THRONG_SANITIZE)
    target_compile_options(${target} PRIVATE $<$<COMPILE_LANGUAGE:CXX>:${THRONG_SANITIZER_FLAGS}>)
    # A sanitized static library needs the sanitizer runtimes wherever it is
    # linked: consumers of a library (also the installed package) get the flags.
    get_target_property(type ${target} TYPE)
    if(type STREQUAL "STATIC_LIBRARY")
      target_link_options(${target} PUBLIC ${THRONG_SANITIZER_FLAGS})
    else()
      target_link_options(${target} PRIVATE ${THRONG_SANITIZER_FLAGS})
    endif()
  endif()
endfunction()

# throng_kernel_sources(file...): sources whose parallel_for bodies must also
# run on the GPU. They are ordinary C++ files; with THRONG_CUDA they are
# compiled by nvcc so the same lambda becomes a CUDA kernel.
function(throng_kernel_sources)
  if(THRONG_CUDA)
    set_source_files_properties(${ARGN} PROPERTIES LANGUAGE CUDA)
  endif()
endfunction()

# throng_test(name source... LIBS lib...): one GoogleTest executable.
function(throng_test name)
  cmake_parse_arguments(T "" "" "LIBS" ${ARGN})
  add_executable(${name} ${T_UNPARSED_ARGUMENTS})
  target_link_libraries(${name} PRIVATE ${T_LIBS} GTest::gtest GTest::gtest_main)
  # Test data is found from the source folder, never from __FILE__ (which is
  # relative when the compiler is given relative paths, e.g. under ccache).
  target_compile_definitions(${name} PRIVATE THRONG_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  throng_setup_target(${name})
  gtest_discover_tests(${name}
    WORKING_DIRECTORY ${CMAKE_SOURCE_DIR}
    PROPERTIES ENVIRONMENT "THRONG_SHARED_DIR=${CMAKE_SOURCE_DIR}/../shared"
    DISCOVERY_TIMEOUT 60)
endfunction()
