// The raw (uncompressed) payload of one mixed chunk, as .ldc files store it
// before zstd: shared by the .ldc loader (io.cpp, where it is defined) and the
// chunk log (chunk_log.cpp), so both formats hold chunks byte for byte alike.
// Payload, per axis: a uniform flag, the start-inside bits, the point count of
// every ray and the 8-byte points (see io.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "ldc/status.h"
#include "ldc/world.h"

namespace ldc::detail {

// The raw payload of `chunk`, whose families are of chunk size `chunk_size`.
std::vector<uint8_t> chunk_raw_bytes(const Chunk& chunk, int chunk_size);

// Parses a raw payload into `chunk` (bounds-checked: nothing allocated past
// what `size` justifies) and runs validate_chunk on it. Errors (kCorruptData)
// name `at`.
Status decode_chunk(const uint8_t* data, size_t size, int chunk_size, Chunk& chunk, const std::string& at);

}  // namespace ldc::detail
