// The precompiled header of the test targets (TILTCAL_PCH): cmake/pch.h and
// GoogleTest.
#include "cmake/pch.h"

#include <random>

#include <gtest/gtest.h>
