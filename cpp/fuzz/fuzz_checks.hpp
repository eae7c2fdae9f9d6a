// The properties every fuzz input must satisfy, shared by the libFuzzer targets (fuzz_*.cpp) and
// the corpus replay test (cpp/tests/test_fuzz_corpus.cpp, a plain ctest without clang):
//  * checkUrdf: any byte string as URDF text either loads with ok = true and an empty message, or
//    fails with a non-empty message; a loaded chain either is rejected by the solvers with an error
//    code and a message, or solves (frictionless, one constraint, with the URDF's friction and
//    limits) to finite outputs. The same text through treeFromUrdfString: ok with an empty message
//    or a failure with one; a loaded tree's segment order, parent array, q_nr and joint metadata
//    agree (preorder, parents before children, finite friction and ordered limits).
//  * checkSolver: the bytes describe a chain (0..8 segments of any joint type, inertias, frames,
//    rotor inertias — values anywhere from plausible to NaN) and one call of each entry point
//    (ChainHdSolver::solve / CartToJnt / responseColumns, FrictionSolver::solve / gaussValue /
//    linkAccelerations); then, if bytes remain and ask for it, the same segments as a tree (parents
//    drawn) through TreeHdSolver (both solve overloads, up to 13 columns on drawn segments,
//    responseColumns) and FrictionSolver on the tree. Each call returns 0 with finite outputs, or
//    an error code < 0 with a non-empty message.
//  * checkFloating (fuzz_floating_checks.cpp): the bytes describe a tree of 0..8 segments on a
//    free-flyer or planar base (base inertia mostly valid), a base configuration whose quaternion /
//    (cos, sin) is unit, slightly off or anything, and inputs with 0..3 constraint blocks; solve,
//    step, stepSymplectic, integrateConfiguration and the dynamics and momentum companions each
//    succeed with finite outputs or fail with a message, and a finite base configuration off the
//    unit norm by more than 1e-5 is refused (saying "unit" when nothing else is wrong).
// Both return "" when the properties hold, else a description of the violation.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace fuzzutil {

std::string checkUrdf(const std::uint8_t* data, std::size_t size);
std::string checkSolver(const std::uint8_t* data, std::size_t size);
std::string checkFloating(const std::uint8_t* data, std::size_t size);

}  // namespace fuzzutil
