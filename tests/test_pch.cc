// the one translation unit that builds tests/test_pch.h's precompiled header (CMakeLists.txt);
// the <module>_tests reuse it
