// clocked_top.h: ClockedTop now lives in tb/stream_shim.h with the other pieces every shim shares
// (that header enters every variant's build stamp). This name stays while tb-rs/build.rs lists it.
#pragma once

#include "stream_shim.h"
