# The render family's system libraries: OpenGL (libglvnd's libOpenGL) and EGL
# for headless contexts, GLFW and Dear ImGui for the viewer, stb for PNG.
# Sets THRONG_RENDER_LIBS. With THRONG_RENDER=ON (the default) a missing
# library stops the configure step with the Debian package that provides it;
# -DTHRONG_RENDER=OFF builds everything else without the renderer.
option(THRONG_RENDER "Build the OpenGL renderer, headless video and viewer (src/render)" ON)
set(THRONG_RENDER_LIBS "")
if(THRONG_FUZZ)
  set(THRONG_RENDER OFF)  # fuzz targets parse input; they need no renderer
endif()
if(NOT THRONG_RENDER)
  message(STATUS "throng: renderer off: no `throng view`, no video")
  return()
endif()

set(OpenGL_GL_PREFERENCE GLVND)
find_package(OpenGL COMPONENTS OpenGL EGL)
find_package(glfw3 3.3 QUIET)
find_package(PkgConfig QUIET)
if(PkgConfig_FOUND)
  pkg_check_modules(THRONG_IMGUI QUIET IMPORTED_TARGET imgui)
  pkg_check_modules(THRONG_STB QUIET IMPORTED_TARGET stb)
endif()

set(missing "")
if(NOT TARGET OpenGL::OpenGL)
  list(APPEND missing "libOpenGL (libopengl-dev, libgl-dev)")
endif()
if(NOT TARGET OpenGL::EGL)
  list(APPEND missing "libEGL (libegl-dev)")
endif()
if(NOT TARGET glfw)
  list(APPEND missing "GLFW 3.3 (libglfw3-dev)")
endif()
if(NOT TARGET PkgConfig::THRONG_IMGUI)
  list(APPEND missing "Dear ImGui (libimgui-dev)")
endif()
if(NOT TARGET PkgConfig::THRONG_STB)
  list(APPEND missing "stb (libstb-dev)")
endif()
if(missing)
  string(REPLACE ";" ", " missing_text "${missing}")
  message(FATAL_ERROR "throng: the renderer needs ${missing_text}. Install them with "
                      "`bash scripts/setup.sh --deps` (Debian packages in scripts/packages.txt), "
                      "or configure with -DTHRONG_RENDER=OFF to build without the renderer.")
endif()
# One space-separated string: src/CMakeLists.txt splits it with separate_arguments.
set(THRONG_RENDER_LIBS "OpenGL::OpenGL OpenGL::EGL glfw PkgConfig::THRONG_IMGUI PkgConfig::THRONG_STB")
