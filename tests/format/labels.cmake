# SPDX-License-Identifier: MIT
# Labels of the format layer's tests (tests/CMakeLists.txt says what each label means).
cbrdf_label_tests(real-data [=[RealDataMerl\..*]=])
