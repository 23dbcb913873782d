#pragma once
// the realtime tier of the transport, every stage (one include for the kernels and the host
// renderer that chain them): the surface loop (realtime_shading.h), the shared visibility
// (realtime_visibility.h), the mirror layer (realtime_mirror.h), the particle streaks
// (realtime_streaks.h), the media (realtime_media.h) and the film (realtime_develop.h).

#include "penumbra/render/transport/realtime_develop.h"
#include "penumbra/render/transport/realtime_media.h"
#include "penumbra/render/transport/realtime_mirror.h"
#include "penumbra/render/transport/realtime_shading.h"
#include "penumbra/render/transport/realtime_streaks.h"
#include "penumbra/render/transport/realtime_visibility.h"

namespace penumbra::cuda {}  // namespace penumbra::cuda
