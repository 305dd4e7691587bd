// ULC's version, kept in step with project(VERSION) in the top-level CMakeLists.txt.
#pragma once

#define ULC_VERSION_MAJOR 0
#define ULC_VERSION_MINOR 1
#define ULC_VERSION_PATCH 0
#define ULC_VERSION_STRING "0.1.0"
