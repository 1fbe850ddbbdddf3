// CRC-32 for modules beside the core (the tool's bake manifests): the core's
// own ldc/detail/crc32.h (IEEE 802.3, reflected, as zlib's crc32), shared here
// as ldc/internal/README.md says, so that no module includes ldc/detail/.
#pragma once

#include "ldc/detail/crc32.h"
