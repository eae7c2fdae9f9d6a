// Kept for the files that include it: the companions' declarations live in companions.hpp.
#pragma once

#include "companions.hpp"
