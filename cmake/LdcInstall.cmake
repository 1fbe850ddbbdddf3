# Install rules and the CMake package: `cmake --install build --prefix P` puts
#   P/include/ldc/<module>/*.h          public headers only (no detail/, no internal/)
#   P/lib/libldc_*.a, P/lib/libldc_c.so* the libraries
#   P/lib/cmake/ldc/ldcConfig.cmake, ldcConfigVersion.cmake, ldcTargets-<component>.cmake
#   P/bin/ldc, P/lib/ldc/ldc-vdb.so    the tool and its OpenVDB plugin (loaded for .vdb output only)
# and `find_package(ldc 0.3 COMPONENTS core contour ...)` then gives the
# ldc::<component> targets asked for and finds only what those need (see
# ldcConfig.cmake.in); without COMPONENTS every component that was built.
#
# Components, each its own export set (ldcTargets-<component>.cmake):
#   core, contour, contour_openmesh, meshio, csg, nav, voxelize,
#   voxelize_vdb (when built with OpenVDB), live, gi_cpu, gi (when built with
#   Vulkan), render, c (the C API: a shared library that needs no dev package).
#
# Headers keep the paths the sources use ("ldc/world.h", "csg/csg.h"): the
# installed targets add P/include/ldc to the include path, so consumers write
# the same #include lines as the library's own code and nothing lands directly
# in P/include (no clash with other projects' "nav/" or "csg/" folders).
# No public header includes CGAL, OpenVDB, Embree, a detail/ header or
# internal/ (tests/install checks it).
include(CMakePackageConfigHelpers)

set(LDC_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/ldc CACHE STRING
    "Where ldcConfig.cmake is installed, relative to the prefix")
set(ldc_header_dir ${CMAKE_INSTALL_INCLUDEDIR}/ldc)
set(LDC_PACKAGE_COMPONENTS "")

# ldc_install_component(NAME target HEADERS dir/a.h ...): target -> ldc::NAME,
# its headers, and its own export set.
function(ldc_install_component name target)
  cmake_parse_arguments(C "" "" "HEADERS" ${ARGN})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name})
  install(TARGETS ${target} EXPORT ldcTargets-${name}
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT runtime NAMELINK_COMPONENT dev
          RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime
          INCLUDES DESTINATION ${ldc_header_dir})
  install(EXPORT ldcTargets-${name} NAMESPACE ldc:: DESTINATION ${LDC_INSTALL_CMAKEDIR} COMPONENT dev)
  foreach(header ${C_HEADERS})
    get_filename_component(dir ${header} DIRECTORY)
    install(FILES ${header} DESTINATION ${ldc_header_dir}/${dir} COMPONENT dev)
  endforeach()
  set(LDC_PACKAGE_COMPONENTS ${LDC_PACKAGE_COMPONENTS} ${name} PARENT_SCOPE)
endfunction()

ldc_install_component(core ldc_core HEADERS ldc/build.h ldc/context.h ldc/io.h ldc/materials.h ldc/mesh.h
  ldc/query.h ldc/status.h ldc/terrain.h ldc/version.h ldc/world.h
  ldc/lod.h ldc/chunk_source.h ldc/chunk_log.h ldc/store.h)
ldc_install_component(contour ldc_contour HEADERS contour/contour.h)
ldc_install_component(contour_openmesh ldc_contour_openmesh HEADERS contour/openmesh.h)
ldc_install_component(meshio ldc_meshio HEADERS meshio/meshio.h contour/export.h)  # export.h: deprecated forward
ldc_install_component(csg ldc_csg HEADERS csg/csg.h)
ldc_install_component(nav ldc_nav HEADERS nav/nav.h)
ldc_install_component(voxelize ldc_voxelize HEADERS voxelize/voxelize.h)
if(TARGET ldc_voxelize_vdb)
  ldc_install_component(voxelize_vdb ldc_voxelize_vdb HEADERS voxelize/vdb.h)
endif()
ldc_install_component(live ldc_live HEADERS live/live.h)
# gi_bridge/: the CPU engine always, the Vulkan engine when built. The
# Embree path tracer (ldc_gi_reference) is a test and benchmark tool and is
# not installed.
ldc_install_component(gi_cpu ldc_gi_cpu HEADERS gi_bridge/gi.h)
if(TARGET ldc_gi)
  ldc_install_component(gi ldc_gi)
endif()
ldc_install_component(render ldc_render HEADERS render/render.h)
if(TARGET ldc_c)
  ldc_install_component(c ldc_c HEADERS capi/ldc.h)
endif()

configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/ldcConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/ldcConfig.cmake INSTALL_DESTINATION ${LDC_INSTALL_CMAKEDIR})
# 0.x: a consumer asking for 0.3 accepts 0.3.* only (minor bumps may change
# the C++ API before 1.0); from 1.0 on, SameMajorVersion is the promise.
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/ldcConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/ldcConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/ldcConfigVersion.cmake
        DESTINATION ${LDC_INSTALL_CMAKEDIR} COMPONENT dev)
if(TARGET ldc_tool)
  install(TARGETS ldc_tool RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT tools)
  # The OpenVDB plugin that `ldc voxelize -o X.vdb` loads, where the tool
  # looks for it: <libdir>/ldc (its LDC_INSTALL_DIR, voxelize/CMakeLists.txt).
  get_target_property(ldc_vdb_plugin_dir ldc_vdb_plugin LDC_INSTALL_DIR)
  install(TARGETS ldc_vdb_plugin LIBRARY DESTINATION ${ldc_vdb_plugin_dir} COMPONENT tools)
  # The other plugins (issue 22), likewise at their LDC_INSTALL_DIR: Draco
  # (meshio/CMakeLists.txt), the Vulkan GI engine and the path-traced
  # reference (gi_bridge/CMakeLists.txt), where built.
  foreach(plugin ldc_draco_plugin ldc_gi_vulkan_plugin ldc_gi_reference_plugin)
    if(TARGET ${plugin})
      get_target_property(plugin_dir ${plugin} LDC_INSTALL_DIR)
      install(TARGETS ${plugin} LIBRARY DESTINATION ${plugin_dir} COMPONENT tools)
    endif()
  endforeach()
endif()
