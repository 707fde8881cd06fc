// Empty: the targets that own the precompiled headers the others reuse
// (tiltcal_pch, tiltcal_test_pch in cmake/tiltcal_helpers.cmake).
