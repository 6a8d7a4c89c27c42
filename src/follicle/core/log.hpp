#pragma once
// Logging goes through the Context's spdlog logger: ctx.log().info("...").
#include <spdlog/spdlog.h>

#include "follicle/core/context.hpp"
