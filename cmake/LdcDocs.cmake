# The API reference: `cmake --build build --target docs` runs Doxygen over the
# public headers and docs/*.md into build/docs/html (index.html). The target
# exists only when Doxygen is found (Debian: apt-get install doxygen; it is not
# in scripts/install-deps.sh, so the default build and CI do not need it).
find_package(Doxygen QUIET)
if(DOXYGEN_FOUND)
  set(LDC_DOXYGEN_INPUT
    ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/CHANGELOG.md ${PROJECT_SOURCE_DIR}/docs
    ${PROJECT_SOURCE_DIR}/ldc ${PROJECT_SOURCE_DIR}/contour ${PROJECT_SOURCE_DIR}/csg
    ${PROJECT_SOURCE_DIR}/nav ${PROJECT_SOURCE_DIR}/voxelize ${PROJECT_SOURCE_DIR}/capi)
  string(REPLACE ";" " " LDC_DOXYGEN_INPUT "${LDC_DOXYGEN_INPUT}")
  set(LDC_DOXYGEN_HAVE_DOT NO)
  if(DOXYGEN_DOT_FOUND)
    set(LDC_DOXYGEN_HAVE_DOT YES)  # include graphs when Graphviz is there
  endif()
  configure_file(${PROJECT_SOURCE_DIR}/docs/Doxyfile.in ${PROJECT_BINARY_DIR}/Doxyfile @ONLY)
  add_custom_target(docs
    COMMAND ${CMAKE_COMMAND} -E make_directory ${PROJECT_BINARY_DIR}/docs
    COMMAND ${DOXYGEN_EXECUTABLE} ${PROJECT_BINARY_DIR}/Doxyfile
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
    COMMENT "Doxygen API reference -> ${PROJECT_BINARY_DIR}/docs/html/index.html"
    VERBATIM)
  message(STATUS "  docs            target 'docs' (Doxygen ${DOXYGEN_VERSION})")
else()
  message(STATUS "  docs            Doxygen not found: no 'docs' target")
endif()
