# SPDX-License-Identifier: MIT
# Labels of the encoder's tests (tests/CMakeLists.txt says what each label means).

# Left to the release suite: each repeats, on more or larger data or more often, code that other
# tests run under the sanitizers too. The mixture fit at 8 table scales, as a component ladder and
# over component counts (Mixture.NotMeasuredBins..., .Deterministic... and .EncodedFile... run
# there); the fit of every family to choose one (each family's fit runs in Fit.* and
# NumericHardening.*); rate control's searches and the residual's byte budget
# (RateControl.Unreachable..., .Secant..., ResidualBudget.MaxError..., NoiseLadder.NoisySample...
# and UnreachableTarget.* run there); the claims measured over the 20 real materials (the same
# code runs there on synthetic tables); three of Slicing's seven tests, one of SphereScorer's two
# and Sampling's chi-square over several materials (its batch-path twin runs there); the network
# tabulated twice to compare (once in Nbrdf.TableHolds...); the noise estimate at 1% and 5%
# (3% runs there).
cbrdf_label_tests(slow
  [=[FitScale\.MixtureFitDoesNotDependOnTheTableScale]=]
  [=[Mixture\.FitLadderEqualsSeparateFitsAndReusesTheFactorization]=]
  [=[Mixture\.MoreComponentsNeverFitWorse]=]
  [=[Mixture\.AutoComponentsStopWhenAComponentDoesNotPay]=]
  [=[Mixture\.MixturesWithoutCopulaFitKeepIndependenceAndTheFactorization]=]
  [=[Mixture\.RecoversATwoComponentTableThatOneComponentCannot]=]
  [=[Fit\.AutoFamilyPicksTheFamilyThatMadeTheData]=]
  [=[RateControl\.LadderPutsTheResidualOnTheOneComponentModelBeyondTheModelsReach]=]
  [=[RateControl\.PruningKeepsTheBestSettingOfTheExhaustiveSearch]=]
  [=[RateControl\.SearchReusesFitsAndStopsWhenBracketed]=]
  [=[RateControl\.ByteBudgetAndPsnrTargetPickTheBestSettingTried]=]
  [=[ResidualBudget\.ByteBudgetUsesTheResidualLayer]=]
  [=[RealDataModel\..*]=]
  [=[Residual\.BoundHeldOnEveryRealMaterial]=]
  [=[CodecIoMeasure\.BytesAndErrorPerBitRealMaterials]=]
  [=[Slicing\.NotMeasuredBinsDoNotMoveBoundaries]=]
  [=[Slicing\.SeparableTableGetsNearUniformSlices]=]
  [=[Slicing\.BoundariesConcentrateWhereTheShapeChanges]=]
  [=[SphereScorer\.ScoresEqualSpherePsnrOnTheDecodedTable]=]
  [=[Sampling\.ChiSquareAgainstPdfForSeveralMaterialsAndDirections]=]
  [=[Nbrdf\.TableIsBitForBitDeterministic]=]
  [=[Sigmas/NoiseReal\.EstimateWithinAQuarterOfTheInjectedNoise/"0\.0[15]"]=]
  [=[NoiseLadder\.RealFabricAtThreePercent]=])

cbrdf_label_tests(real-data
  [=[RealDataModel\..*]=]
  [=[Residual\.BoundHeldOnEveryRealMaterial]=]
  [=[CodecIoMeasure\.BytesAndErrorPerBitRealMaterials]=]
  [=[Sigmas/NoiseReal\..*]=]
  [=[NoiseLadder\.RealFabricAtThreePercent]=]
  [=[Samples\.MaskMatchesARealFile]=]
  [=[Nbrdf\.AgreesWithTheSharedGenerator]=])

# These run the cbrdf command.
cbrdf_label_tests(cli
  [=[NoiseCli\..*]=]
  [=[Residual\.OptionsAreCheckedWithOneLineMessages]=])
