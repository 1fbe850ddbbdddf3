# Install rules and the CMake package: `cmake --install build --prefix P` puts
#   P/include/ldc/{ldc,contour,csg,nav,voxelize,live,capi}/*.h   public headers only
#   P/lib/libldc_*.a, P/lib/libldc_c.so*                    the libraries
#   P/lib/cmake/ldc/ldcConfig.cmake, ldcConfigVersion.cmake, ldcTargets*.cmake
# and `find_package(ldc 0.2)` then gives ldc::core, ldc::contour, ldc::csg,
# ldc::nav, ldc::voxelize, ldc::live, ldc::voxelize_vdb (when it was built), ldc::c (the
# C API) and ldc::gi (only when gi_bridge/ was built, with Vulkan).
#
# Headers keep the paths the sources use ("ldc/world.h", "csg/csg.h"): the
# installed targets add P/include/ldc to the include path, so consumers write
# the same #include lines as the library's own code and nothing lands directly
# in P/include (no clash with other projects' "nav/" or "csg/" folders).
# No public header includes CGAL, OpenVDB, Embree or a detail/ header
# (tests/install checks it); contour/openmesh.h needs OpenMesh, which a
# consumer of ldc::contour finds anyway (see ldcConfig.cmake.in).
include(CMakePackageConfigHelpers)

set(LDC_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/ldc CACHE STRING
    "Where ldcConfig.cmake is installed, relative to the prefix")
set(ldc_header_dir ${CMAKE_INSTALL_INCLUDEDIR}/ldc)

# Module target -> exported name (ldc::<name>) and its public headers.
set(ldc_export_targets ldc_core ldc_contour ldc_csg ldc_nav ldc_voxelize ldc_live)
set_target_properties(ldc_core PROPERTIES EXPORT_NAME core)
set_target_properties(ldc_contour PROPERTIES EXPORT_NAME contour)
set_target_properties(ldc_csg PROPERTIES EXPORT_NAME csg)
set_target_properties(ldc_nav PROPERTIES EXPORT_NAME nav)
set_target_properties(ldc_voxelize PROPERTIES EXPORT_NAME voxelize)
set_target_properties(ldc_live PROPERTIES EXPORT_NAME live)
install(FILES ldc/build.h ldc/context.h ldc/io.h ldc/materials.h ldc/mesh.h ldc/query.h ldc/status.h
              ldc/terrain.h ldc/version.h ldc/world.h
        DESTINATION ${ldc_header_dir}/ldc COMPONENT dev)
install(FILES contour/contour.h contour/export.h contour/openmesh.h
        DESTINATION ${ldc_header_dir}/contour COMPONENT dev)
install(FILES csg/csg.h DESTINATION ${ldc_header_dir}/csg COMPONENT dev)
install(FILES nav/nav.h DESTINATION ${ldc_header_dir}/nav COMPONENT dev)
install(FILES voxelize/voxelize.h DESTINATION ${ldc_header_dir}/voxelize COMPONENT dev)
install(FILES live/live.h DESTINATION ${ldc_header_dir}/live COMPONENT dev)
list(APPEND ldc_export_targets ldc_render)
set_target_properties(ldc_render PROPERTIES EXPORT_NAME render)
install(FILES render/render.h DESTINATION ${ldc_header_dir}/render COMPONENT dev)
set(LDC_PACKAGE_HAS_VDB OFF)
if(TARGET ldc_voxelize_vdb)
  set(LDC_PACKAGE_HAS_VDB ON)
  list(APPEND ldc_export_targets ldc_voxelize_vdb)
  set_target_properties(ldc_voxelize_vdb PROPERTIES EXPORT_NAME voxelize_vdb)
  install(FILES voxelize/vdb.h DESTINATION ${ldc_header_dir}/voxelize COMPONENT dev)
endif()
set(LDC_PACKAGE_HAS_C OFF)
if(TARGET ldc_c)
  set(LDC_PACKAGE_HAS_C ON)
  list(APPEND ldc_export_targets ldc_c)
  set_target_properties(ldc_c PROPERTIES EXPORT_NAME c)
  install(FILES capi/ldc.h DESTINATION ${ldc_header_dir}/capi COMPONENT dev)
endif()
# gi_bridge/ (issue 8): the CPU engine ldc::gi_cpu always, and the Vulkan
# engine ldc::gi when it was built (LDC_WITH_VULKAN); ldcConfig.cmake then
# finds Vulkan for it. The Embree path tracer (ldc_gi_reference) is a test
# and benchmark tool and is not installed.
list(APPEND ldc_export_targets ldc_gi_cpu)
set_target_properties(ldc_gi_cpu PROPERTIES EXPORT_NAME gi_cpu)
install(FILES gi_bridge/gi.h DESTINATION ${ldc_header_dir}/gi_bridge COMPONENT dev)
set(LDC_PACKAGE_HAS_GI OFF)
if(TARGET ldc_gi)
  set(LDC_PACKAGE_HAS_GI ON)
  list(APPEND ldc_export_targets ldc_gi)
  set_target_properties(ldc_gi PROPERTIES EXPORT_NAME gi)
endif()

install(TARGETS ${ldc_export_targets} EXPORT ldcTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT runtime NAMELINK_COMPONENT dev
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime
        INCLUDES DESTINATION ${ldc_header_dir})
install(EXPORT ldcTargets NAMESPACE ldc:: DESTINATION ${LDC_INSTALL_CMAKEDIR} COMPONENT dev)

configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/ldcConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/ldcConfig.cmake INSTALL_DESTINATION ${LDC_INSTALL_CMAKEDIR})
# 0.x: a consumer asking for 0.2 accepts 0.2.* only (minor bumps may change
# the C++ API before 1.0); from 1.0 on, SameMajorVersion is the promise.
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/ldcConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/ldcConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/ldcConfigVersion.cmake
        DESTINATION ${LDC_INSTALL_CMAKEDIR} COMPONENT dev)
if(TARGET ldc_tool)
  install(TARGETS ldc_tool RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT tools)
endif()
