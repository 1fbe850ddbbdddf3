// tinygltf in a namespace of ldc's own, ldc_tinygltf.
//
// Why not Debian's libtinygltf.so: libdraco 1.5.5 is built with its
// transcoder and exports its own, older copy of tinygltf (117 symbols in
// namespace tinygltf, with other struct layouts). In a program that links
// both, which copy a call reaches depends on the link order, and the wrong
// one crashes (seen: TinyGLTF::LoadBinaryFromFile resolved into libdraco).
// Under a renamed namespace nothing can interpose ldc's copy. Its
// implementation is compiled once, in gltf.cpp.
//
// Images are never decoded or written (ldc writes none and ignores those of
// files it reads), so STB is left out; JSON is nlohmann's.
#pragma once

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#define tinygltf ldc_tinygltf
#include <tiny_gltf.h>
#undef tinygltf
