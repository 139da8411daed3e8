# Shared build settings for every throng target.

set(THRONG_WARNINGS -Wall -Wextra -Wpedantic -Wshadow -Wconversion-null -Wno-unused-parameter)
if(THRONG_WERROR)
  list(APPEND THRONG_WARNINGS -Werror)
endif()
set(THRONG_SANITIZER_FLAGS -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all)

# The instruction set: this machine's by default (-march=native: AVX2, FMA
# where the CPU has them), the x86-64 baseline with THRONG_PORTABLE=ON for
# binaries that run elsewhere. Neither fuses a * b + c into one rounding in
# host code (-ffp-contract=off; also asked of code that includes the
# installed headers), so on one machine the instruction set changes speed,
# not results: both builds give the same trajectories and poses bit for bit
# (the recorded run test holds in each). CUDA device code keeps nvcc's fused
# multiply-adds: the GPU matches the CPU to tolerances, not bits. Nothing
# reads errno, so square roots need not set it (-fno-math-errno): they stay
# one instruction and loops over lanes of them vectorise; results are the same.
option(THRONG_PORTABLE "Build for the x86-64 baseline instead of this machine's instruction set" OFF)
set(THRONG_ARCH_FLAGS -ffp-contract=off -fno-math-errno)
if(NOT THRONG_PORTABLE)
  include(CheckCXXCompilerFlag)
  check_cxx_compiler_flag(-march=native THRONG_HAS_MARCH_NATIVE)
  if(THRONG_HAS_MARCH_NATIVE)
    list(APPEND THRONG_ARCH_FLAGS -march=native)
  endif()
endif()
list(JOIN THRONG_ARCH_FLAGS "," THRONG_ARCH_FLAGS_CUDA_HOST)

# throng_setup_target(target): warnings, sanitizers and include path.
function(throng_setup_target target)
  target_compile_options(${target} PRIVATE $<$<COMPILE_LANGUAGE:CXX>:${THRONG_WARNINGS} ${THRONG_ARCH_FLAGS}>)
  if(THRONG_CUDA)
    target_compile_options(${target} PRIVATE
      $<$<COMPILE_LANGUAGE:CUDA>:--extended-lambda --expt-relaxed-constexpr -Xcompiler=-Wall,${THRONG_ARCH_FLAGS_CUDA_HOST}>)
  endif()
  get_target_property(type ${target} TYPE)
  if(type STREQUAL "STATIC_LIBRARY")
    # The headers' inline code compiled in a consumer must round as ours does.
    target_compile_options(${target} INTERFACE $<$<COMPILE_LANGUAGE:CXX>:-ffp-contract=off>)
  endif()
  if(THRONG_SANITIZE)
    target_compile_options(${target} PRIVATE $<$<COMPILE_LANGUAGE:CXX>:${THRONG_SANITIZER_FLAGS}>)
    # A sanitized static library needs the sanitizer runtimes wherever it is
    # linked: consumers of a library (also the installed package) get the flags.
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
