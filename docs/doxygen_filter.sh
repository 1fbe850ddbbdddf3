#!/bin/sh
# Doxygen INPUT_FILTER for ldc's headers, which are documented with plain //
# comments (STYLE.md): the comment block at the top of a file becomes its
# \file description, other // lines become /// and a comment after a
# declaration on the same line becomes ///< (the member's description).
# Section rulers (// ----) are dropped. In the C header (capi/ldc.h) /* */
# comments become /** */ and /**< */ the same way. Markdown passes through.
case "$1" in
  *.md) cat "$1"; exit 0 ;;
esac
awk '
  BEGIN { top = 1 }
  top && /^\/\/ ?/ { line = $0; sub(/^\/\/ ?/, "", line); if (!started) { print "/// \\file"; started = 1 } print "/// " line; next }
  top && !/^\/\/ ?/ { top = 0 }
  /^[ \t]*\/\/ ?-+[ \t]*$/ { print ""; next }
  /^[ \t]*\/\// { sub(/\/\//, "///"); print; next }
  /[;,{][ \t]+\/\/ / { sub(/[ \t]+\/\/ /, "  ///< "); print; next }
  NR == 1 && /^\/\* / { sub(/^\/\* /, "/** \\file "); print; next }
  /^[ \t]*\/\* / { sub(/\/\* /, "/** "); print; next }
  /[;,][ \t]+\/\* / { sub(/[ \t]+\/\* /, "  /**< "); print; next }
  { print }
' "$1"
