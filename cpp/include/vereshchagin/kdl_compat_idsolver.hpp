/// @file
/// Drop-in for KDL 1.5.1's <kdl/chainidsolver_vereshchagin.hpp>: the deprecated name
/// vereshchagin::kdl_compat::ChainIdSolver_Vereshchagin (was KDL::ChainIdSolver_Vereshchagin), the
/// same class as vereshchagin::kdl_compat::ChainHdSolver_Vereshchagin (kdl_compat.hpp), marked
/// [[deprecated]] as KDL renamed it in 1.5.
#pragma once

#include "vereshchagin/kdl_compat.hpp"
