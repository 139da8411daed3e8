# `cmake --install BUILD --prefix PREFIX`: the library as a package others
# build against.
#   include/throng/<family>/*.h   headers (they include each other as
#                                 "core/buffer.h": include/throng is the
#                                 consumer's include directory)
#   lib/libthrong_<family>.a      one static library per family
#   bin/throng                    the executable
#   lib/cmake/throng/             throngConfig.cmake, throngConfigVersion.cmake,
#                                 throngTargets*.cmake: find_package(throng)
#                                 gives throng::core, throng::motion,
#                                 throng::sim, throng::anim, throng::path,
#                                 throng::io (and throng::render when built)
#   lib/pkgconfig/throng.pc       the same for pkg-config
#   lib/python3.X/dist-packages/  the Python module, when built
#                                 (src/python/CMakeLists.txt)
# Tests, benches and fuzz targets are not installed; the built-in scenarios
# are compiled into throng_io.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

get_property(throng_libraries GLOBAL PROPERTY THRONG_LIBRARIES)
foreach(lib ${throng_libraries})
  string(REGEX REPLACE "^throng_" "" family ${lib})
  file(GLOB headers CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/${family}/*.h)
  install(FILES ${headers} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/throng/${family})
endforeach()

install(TARGETS ${throng_libraries} EXPORT throngTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
if(TARGET throng)
  install(TARGETS throng RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()

set(THRONG_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/throng)
install(EXPORT throngTargets NAMESPACE throng:: FILE throngTargets.cmake
        DESTINATION ${THRONG_INSTALL_CMAKEDIR})

if(TARGET throng_render)
  set(THRONG_PACKAGE_RENDER ON)
else()
  set(THRONG_PACKAGE_RENDER OFF)
endif()
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/throngConfig.cmake.in
  ${PROJECT_BINARY_DIR}/package/throngConfig.cmake
  INSTALL_DESTINATION ${THRONG_INSTALL_CMAKEDIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/package/throngConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/package/throngConfig.cmake
              ${PROJECT_BINARY_DIR}/package/throngConfigVersion.cmake
        DESTINATION ${THRONG_INSTALL_CMAKEDIR})

# pkg-config: the libraries in link order (a family before what it uses).
set(pc_libs "")
set(pc_requires "tbb fmt spdlog yaml-cpp glm nlohmann_json sqlite3 tinygltf")
foreach(family render io path anim sim motion core)
  if(TARGET throng_${family})
    string(APPEND pc_libs " -lthrong_${family}")
  endif()
endforeach()
if(THRONG_PACKAGE_RENDER)
  string(APPEND pc_requires " opengl egl glfw3 imgui stb")
endif()
# As the libraries' INTERFACE options (ThrongTargets.cmake): inline code in
# the headers rounds as it does in the libraries.
set(pc_cflags " -ffp-contract=off")
if(THRONG_CUDA)
  string(APPEND pc_cflags " -DTHRONG_HAVE_CUDA")
  string(APPEND pc_libs " -L${CUDAToolkit_LIBRARY_DIR} -lcudart")
endif()
if(THRONG_SANITIZE)
  string(APPEND pc_cflags " -DTHRONG_CHECK_BOUNDS")
  list(JOIN THRONG_SANITIZER_FLAGS " " sanitizer_flags)
  string(APPEND pc_libs " ${sanitizer_flags}")
endif()
set(THRONG_PC_LIBS "${pc_libs}")
set(THRONG_PC_CFLAGS "${pc_cflags}")
set(THRONG_PC_REQUIRES "${pc_requires}")
configure_file(${PROJECT_SOURCE_DIR}/cmake/throng.pc.in ${PROJECT_BINARY_DIR}/package/throng.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/package/throng.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
