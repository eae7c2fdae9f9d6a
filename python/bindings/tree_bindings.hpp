// The Python Tree (PyTree, model_class.hpp) for the files that use it; bound in model_bindings.cpp.
#pragma once

#include "model_class.hpp"
