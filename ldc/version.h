// The library's version and the .ldc file format version.
//
// LDC_VERSION_MAJOR/MINOR/PATCH follow semantic versioning once 1.0 is out;
// before that, a MINOR bump may change the C++ API (the C API in capi/ldc.h
// keeps its own compatibility promise, see docs/capi.md). This file is the
// single source of the number: the top-level CMakeLists.txt reads it into
// project(VERSION), so the installed ldcConfigVersion.cmake, the shared C
// library's SONAME and these macros cannot disagree. CHANGELOG.md lists what
// each version changed.
//
// LDC_FORMAT_VERSION is the version of the .ldc file layout that save_world
// writes (ldc/io.h: kLdcFormatVersion, the same number). load_world reads
// that version only and refuses others with a message naming both numbers.
//
// Plain macros (no C++), so that C code (capi/ldc.h) can include it too.
#pragma once

#define LDC_VERSION_MAJOR 0
#define LDC_VERSION_MINOR 3
#define LDC_VERSION_PATCH 0
#define LDC_VERSION_STRING "0.3.0"

// One number for comparisons: major * 10000 + minor * 100 + patch.
#define LDC_VERSION (LDC_VERSION_MAJOR * 10000 + LDC_VERSION_MINOR * 100 + LDC_VERSION_PATCH)

#define LDC_FORMAT_VERSION 1
