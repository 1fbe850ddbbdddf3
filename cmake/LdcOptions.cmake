# Compiler warnings and sanitizer flags shared by every ldc target.
add_library(ldc_build_flags INTERFACE)
if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
  target_compile_options(ldc_build_flags INTERFACE
    $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
      -Wcast-align -Woverloaded-virtual -Wimplicit-fallthrough
      -Wno-missing-field-initializers>  # designated initializers of config structs
    -ffp-contract=off)  # no fused multiply-add: the same bits on every machine
endif()
if(LDC_WERROR AND CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
  target_compile_options(ldc_build_flags INTERFACE -Werror)
  # GCC 12's -Wrestrict fires inside std::string's operator+ at -O3 (GCC bug
  # 105329, a false positive in libstdc++): reported, not fatal.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    target_compile_options(ldc_build_flags INTERFACE -Wno-error=restrict)
  endif()
endif()
if(LDC_SANITIZE)
  target_compile_options(ldc_build_flags INTERFACE
    -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  target_link_options(ldc_build_flags INTERFACE -fsanitize=address,undefined)
endif()
