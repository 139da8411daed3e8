# throng_family(name DEPENDS lib...): the library throng_<name> from every
# src/<name>/*.cpp, and the test executable <name>_tests from every
# tests/<name>/*_test.cpp. Sources named *_kernels.cpp hold parallel_for
# bodies that must also run on the GPU: CUDA builds compile them with nvcc.
function(throng_family name)
  cmake_parse_arguments(F "" "" "DEPENDS;TEST_DEPENDS" ${ARGN})
  set(dir ${PROJECT_SOURCE_DIR}/src/${name})
  file(GLOB sources CONFIGURE_DEPENDS ${dir}/*.cpp)
  file(GLOB kernels CONFIGURE_DEPENDS ${dir}/*_kernels.cpp)
  if(kernels)
    throng_kernel_sources(${kernels})
  endif()
  add_library(throng_${name} ${sources})
  # Headers include each other as "core/buffer.h": installed under
  # include/throng/<family>/, with include/throng on the consumer's path.
  target_include_directories(throng_${name} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/src> $<INSTALL_INTERFACE:include/throng>)
  target_link_libraries(throng_${name} PUBLIC ${F_DEPENDS})
  target_compile_features(throng_${name} PUBLIC cxx_std_20)
  throng_setup_target(throng_${name})
  # Installed as throng::<name> (cmake/ThrongInstall.cmake).
  set_target_properties(throng_${name} PROPERTIES EXPORT_NAME ${name})
  set_property(GLOBAL APPEND PROPERTY THRONG_LIBRARIES throng_${name})

  file(GLOB tests CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/tests/${name}/*_test.cpp)
  if(tests AND THRONG_TESTS)
    throng_test(${name}_tests ${tests} LIBS throng_${name} ${F_TEST_DEPENDS})
    target_include_directories(${name}_tests PRIVATE ${PROJECT_SOURCE_DIR})
  endif()
endfunction()
