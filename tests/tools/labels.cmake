# SPDX-License-Identifier: MIT
# Labels of the tools' tests (tests/CMakeLists.txt says what each label means). Every one of them
# runs the cbrdf command or links the tools.

# Left to the release suite: the command's mixture and data-chosen slice options (the fits are
# Mixture.*'s and Slicing.*'s under the sanitizers, the command's paths
# Cli.SampleEncodeInfoDecode...'s); the command's unreachable targets end to end (the library's
# searches behind it run in UnreachableTarget.*); the report's end-to-end runs, which repeat
# encodes and decodes the library's own tests run (the report's other tests, and its option
# checks, run under the sanitizers); the sampling study of an encoded fabric (the sampler's own
# tests run there).
cbrdf_label_tests(slow
  [=[Cli\.MixturesAndDataChosenSlices]=]
  [=[TargetCli\.UnreachableTargetsWriteTheClosestFileAndSayWhy]=]
  [=[ReportRun\..*]=]
  [=[ReportResidual\..*]=]
  [=[ReportHtml\..*]=]
  [=[ReportNoise\.LadderAgainstTheTruthMarksTheNoiseFloor]=]
  [=[Ladder\.MeasuresEveryMethodOnASmallSetting]=]
  [=[ReportLossless\..*]=]
  [=[ReportSampling\.FeltIsNoWorseThanCosineAndThe22SamplerWas]=])

cbrdf_label_tests(browser [=[ReportHtml\..*]=])
