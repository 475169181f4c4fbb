#pragma once
// Include this FIRST in every generator source file (before any other
// header), so that the pragmas below cover every function the file defines
// or instantiates, glm's inline vector operations included.
//
// A spec must give bit-identical triangles on every machine. IEEE 754 makes
// +, -, *, / and sqrt exact-rounded, so the only remaining source of
// difference is the compiler contracting a * b + c into one fused
// multiply-add, which it may do whenever the target has FMA (-march=haswell,
// every aarch64). Contraction is therefore switched off here for these
// files, whatever flags the build uses.
#if defined(__clang__)
#pragma clang fp contract(off)
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off")
#endif
