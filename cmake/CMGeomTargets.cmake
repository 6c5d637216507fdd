# Targets of the CMGeom package and helpers used by test/, examples/ and benchmark/.
#
#   CMGeom::CMGeom     INTERFACE: the header library (CGAL, Eigen, TBB).
#   CMGeom::Mesh_IO    compiled: textured-mesh readers/writers and validation (no image library).
#   CMGeom::Image_IO   compiled: images (PNG and JPEG with libpng and libjpeg, other formats through
#                      OpenImageIO), texture loading, OBJ+MTL+PNG output.
#   CMGeom::OSMesa     compiled, optional: the OSMesa backends (Rendering's Renderer, the
#                      Textured_simplification index-texture resampler).
#   CMGeom::Textured_simplification  compiled: explicit instantiations of the simplification
#                      templates for CMGeom's mesh type and default visitor
#                      (src/Textured_simplification/CMakeLists.txt); optional for users, it only
#                      saves compile time.
#   CMGeom::Compact_model  compiled: explicit instantiations of the Compact_model templates for
#                      their common arguments (src/Compact_model/CMakeLists.txt); optional for users,
#                      it only saves compile time.
#
# OpenImageIO costs ~0.2 s start-up and ~260 shared libraries per binary: CMGeom::Image_IO reads
# PNG and JPEG and writes PNG itself, and loads OpenImageIO as a module on the first image of
# another format (cmgeom_image_io_oiio below).

include(GNUInstallDirs)

add_library(CMGeom INTERFACE)
add_library(CMGeom::CMGeom ALIAS CMGeom)
target_include_directories(CMGeom INTERFACE
  $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
  $<INSTALL_INTERFACE:include>)
target_link_libraries(CMGeom INTERFACE CGAL::CGAL CGAL::Eigen3_support CGAL::TBB_support TBB::tbb Threads::Threads)
target_compile_features(CMGeom INTERFACE cxx_std_17)
# No fused multiply-add contraction, even where the target CPU has FMA (-march=native): the CPU
# index-texture resampler must round like the OpenGL one (Osmesa_index_texture_resampler.h), and
# results stay the same across machines. Explicit FMA intrinsics are not affected.
target_compile_options(CMGeom INTERFACE $<$<COMPILE_LANG_AND_ID:CXX,GNU,Clang>:-ffp-contract=off>)
set_target_properties(CMGeom PROPERTIES EXPORT_NAME CMGeom)

# One precompiled header shared (REUSE_FROM) by every CGAL-heavy target of this build: a CGAL
# translation unit costs ~20 s here, the PCH brings that down by a third to a half.
set(CMGEOM_PCH_HEADERS
  <CGAL/Exact_predicates_inexact_constructions_kernel.h>
  <CGAL/Surface_mesh.h>
  <Eigen/Dense>
  <algorithm> <array> <cmath> <cstdint> <fstream> <iostream> <memory> <sstream> <stdexcept>
  <string> <unordered_map> <utility> <vector>)
if(CMGEOM_USE_PCH)
  file(WRITE ${CMAKE_BINARY_DIR}/cmgeom_pch.cpp "// translation unit that owns the shared PCH\n")
  add_library(cmgeom_pch OBJECT ${CMAKE_BINARY_DIR}/cmgeom_pch.cpp)
  target_link_libraries(cmgeom_pch PUBLIC CMGeom::CMGeom)
  target_precompile_headers(cmgeom_pch PRIVATE ${CMGEOM_PCH_HEADERS})
endif()

# cmgeom_use_pch(<target>): make <target> reuse the shared precompiled header.
function(cmgeom_use_pch target)
  if(CMGEOM_USE_PCH)
    # No POSITION_INDEPENDENT_CODE on any PCH user: -fPIC and -fPIE objects cannot share one PCH
    # (the compiler's default, PIE on Debian, is used everywhere).
    target_precompile_headers(${target} REUSE_FROM cmgeom_pch)
  endif()
endfunction()

# ------------------------------------------------------------------ compiled pieces
add_library(CMGeom_Mesh_IO STATIC
  ${PROJECT_SOURCE_DIR}/src/Mesh_IO/obj_io.cpp
  ${PROJECT_SOURCE_DIR}/src/Mesh_IO/off_ply_io.cpp
  ${PROJECT_SOURCE_DIR}/src/Mesh_IO/stl_io.cpp
  ${PROJECT_SOURCE_DIR}/src/Mesh_IO/gltf_io.cpp
  ${PROJECT_SOURCE_DIR}/src/Mesh_IO/gltf_write.cpp
  ${PROJECT_SOURCE_DIR}/src/Mesh_IO/polygon_soup.cpp
  ${PROJECT_SOURCE_DIR}/src/Mesh_IO/textured_mesh.cpp
  ${PROJECT_SOURCE_DIR}/src/Mesh_IO/atomic_file.cpp)
add_library(CMGeom::Mesh_IO ALIAS CMGeom_Mesh_IO)
# (zlib: .obj.gz and the like; Draco: glTF primitives compressed with KHR_draco_mesh_compression)
target_link_libraries(CMGeom_Mesh_IO PUBLIC CMGeom::CMGeom PRIVATE ZLIB::ZLIB draco::draco)
target_include_directories(CMGeom_Mesh_IO PRIVATE ${PROJECT_SOURCE_DIR}/src)
set_target_properties(CMGeom_Mesh_IO PROPERTIES EXPORT_NAME Mesh_IO)
cmgeom_use_pch(CMGeom_Mesh_IO)

# The pixels are read and written by a module linked with OpenImageIO and loaded on first use
# (src/Mesh_IO/image_io_backend.h): programs linking CMGeom::Image_IO do not load OpenImageIO's
# ~260 libraries at start-up, only when they touch an image.
add_library(cmgeom_image_io_oiio MODULE ${PROJECT_SOURCE_DIR}/src/Mesh_IO/image_io_oiio.cpp)
target_link_libraries(cmgeom_image_io_oiio PRIVATE PkgConfig::OIIO)
target_include_directories(cmgeom_image_io_oiio PRIVATE ${PROJECT_SOURCE_DIR}/include ${PROJECT_SOURCE_DIR}/src)
target_compile_features(cmgeom_image_io_oiio PRIVATE cxx_std_17)
set_target_properties(cmgeom_image_io_oiio PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/lib/cmgeom
                                                      CXX_VISIBILITY_PRESET hidden)

add_library(CMGeom_Image_IO STATIC
  ${PROJECT_SOURCE_DIR}/src/Mesh_IO/image_io.cpp
  ${PROJECT_SOURCE_DIR}/src/Mesh_IO/image_io_native.cpp
  ${PROJECT_SOURCE_DIR}/src/Mesh_IO/textured_mesh_io.cpp)
add_library(CMGeom::Image_IO ALIAS CMGeom_Image_IO)
target_link_libraries(CMGeom_Image_IO PUBLIC CMGeom::Mesh_IO PNG::PNG JPEG::JPEG ${CMAKE_DL_LIBS})
target_include_directories(CMGeom_Image_IO PRIVATE ${PROJECT_SOURCE_DIR}/src)
target_compile_definitions(CMGeom_Image_IO PRIVATE
  CMGEOM_IMAGE_IO_MODULE_BUILD_PATH="$<TARGET_FILE:cmgeom_image_io_oiio>"
  CMGEOM_IMAGE_IO_MODULE_INSTALL_PATH="${CMAKE_INSTALL_FULL_LIBDIR}/cmgeom/$<TARGET_FILE_NAME:cmgeom_image_io_oiio>")
add_dependencies(CMGeom_Image_IO cmgeom_image_io_oiio)
set_target_properties(CMGeom_Image_IO PROPERTIES EXPORT_NAME Image_IO)
cmgeom_use_pch(CMGeom_Image_IO)

# Further compiled pieces of later packages add themselves here (see src/<Package>/CMakeLists.txt).
file(GLOB _cmgeom_src_pkgs LIST_DIRECTORIES true ${PROJECT_SOURCE_DIR}/src/*)
foreach(_d ${_cmgeom_src_pkgs})
  if(EXISTS ${_d}/CMakeLists.txt)
    get_filename_component(_n ${_d} NAME)
    add_subdirectory(${_d} ${CMAKE_BINARY_DIR}/src/${_n})
  endif()
endforeach()

# ------------------------------------------------------------------ helpers
# cmgeom_add_package_dirs(<top>): add every <top>/<Package>/ that has a CMakeLists.txt.
function(cmgeom_add_package_dirs top)
  file(GLOB _pkgs LIST_DIRECTORIES true ${PROJECT_SOURCE_DIR}/${top}/*)
  list(SORT _pkgs)
  foreach(_d ${_pkgs})
    if(IS_DIRECTORY ${_d} AND EXISTS ${_d}/CMakeLists.txt)
      add_subdirectory(${_d})
    endif()
  endforeach()
endfunction()

# Test configuration header: where the shared models live and where tests may write.
set(CMGEOM_TEST_TMP_DIR ${CMAKE_BINARY_DIR}/test_tmp)
file(MAKE_DIRECTORY ${CMGEOM_TEST_TMP_DIR})
configure_file(${PROJECT_SOURCE_DIR}/cmake/cmgeom_test_config.h.in
               ${CMAKE_BINARY_DIR}/generated/cmgeom_test_config.h @ONLY)

# cmgeom_test_program_here(<name> <var>): <var> is false when the test program <name> is listed in
# CMGEOM_TEST_PROGRAMS_ELSEWHERE (another build of the same sources runs it; scripts/test.sh leaves
# the programs its AddressSanitizer build runs whole out of the Release build).
function(cmgeom_test_program_here name var)
  if(name IN_LIST CMGEOM_TEST_PROGRAMS_ELSEWHERE)
    set(${var} FALSE PARENT_SCOPE)
  else()
    set(${var} TRUE PARENT_SCOPE)
  endif()
endfunction()

# cmgeom_add_gtest(<name> SOURCES <cpp...> [LIBS <targets...>] [TIMEOUT <s>])
# One GoogleTest executable (group related tests: each CGAL TU costs ~20 s to compile),
# every TEST registered with CTest individually. Nothing is made when the program is in
# CMGEOM_TEST_PROGRAMS_ELSEWHERE (callers test if(TARGET <name>) before adding to it).
function(cmgeom_add_gtest name)
  cmake_parse_arguments(A "" "TIMEOUT" "SOURCES;LIBS" ${ARGN})
  cmgeom_test_program_here(${name} _here)
  if(NOT _here)
    return()
  endif()
  add_executable(${name} ${A_SOURCES})
  target_link_libraries(${name} PRIVATE CMGeom::CMGeom GTest::gtest GTest::gtest_main ${A_LIBS})
  target_include_directories(${name} PRIVATE ${CMAKE_BINARY_DIR}/generated
                                             ${PROJECT_SOURCE_DIR}/test/common)
  cmgeom_use_pch(${name})
  # One source file per component keeps the tests readable, but each file parses CGAL and GTest
  # again: compile them in batches of eight (one unity file each), as the tool does.
  set_target_properties(${name} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
  if(NOT A_TIMEOUT)
    set(A_TIMEOUT 600)
  endif()
  gtest_discover_tests(${name} DISCOVERY_MODE PRE_TEST
    WORKING_DIRECTORY ${CMGEOM_TEST_TMP_DIR}
    PROPERTIES TIMEOUT ${A_TIMEOUT})
endfunction()

# cmgeom_add_example(<name> SOURCES <cpp...> [LIBS ...] [ARGS ...]): built and run by CTest.
function(cmgeom_add_example name)
  cmake_parse_arguments(A "" "" "SOURCES;LIBS;ARGS" ${ARGN})
  add_executable(${name} ${A_SOURCES})
  target_link_libraries(${name} PRIVATE CMGeom::CMGeom ${A_LIBS})
  cmgeom_use_pch(${name})
  add_test(NAME example_${name} COMMAND ${name} ${A_ARGS} WORKING_DIRECTORY ${CMGEOM_TEST_TMP_DIR})
endfunction()

# cmgeom_add_benchmark(<name> SOURCES <cpp...> [LIBS ...]): Google Benchmark program, never run by CTest.
function(cmgeom_add_benchmark name)
  cmake_parse_arguments(A "" "" "SOURCES;LIBS" ${ARGN})
  add_executable(${name} ${A_SOURCES})
  target_link_libraries(${name} PRIVATE CMGeom::CMGeom benchmark::benchmark ${A_LIBS})
  target_include_directories(${name} PRIVATE ${CMAKE_BINARY_DIR}/generated ${PROJECT_SOURCE_DIR}/benchmark/common)
  cmgeom_use_pch(${name})
endfunction()
