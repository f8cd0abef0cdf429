# Included by ctest after the discovered tests (tests/CMakeLists.txt, TEST_INCLUDE_FILES): the
# longest end-to-end tests' costs, so that ctest starts them first. ctest orders tests by the
# times it recorded in the build tree (Testing/Temporary/CTestCostData.txt); a fresh clone has
# none, and with two tests at a time it then began the longest, Demo.WholeChainOnAShortMatch
# (about 4 minutes), near the end: the suite took 713 s there against 557 s in a warm tree. The
# figures are seconds measured on the Intel Xeon (two tests at a time); only their order matters.
# The fits are three tests (oa_dm2, oa_ctf2 hidden, q3dm6ish twice), 102, 78 and 60 s on the AVX2
# AMD EPYC two at a time, times the Xeon's 1.3; one test of 287 s before, the suite's longest.
# A name that is no test's (renamed, removed) is ignored: ctest's set_tests_properties does nothing
# for it here (checked), and if(TEST) is always false in a file ctest reads.
set(dynbench_test_costs
  OpenArena.HiddenLightsAreFoundAgain=130
  OpenArena.FittedLightsReproduceTheLightmapsAndTheLightGrid=100
  OpenArena.AFitIsTheSameBytesOnAnotherMachineAndUnjudged=80
  Demo.WholeChainOnAShortMatch=130
  Slurm.SuiteAsAChainOfJobsGivesTheLocalSuitesNumbers=129
  Suite.SmokeSuiteRunsResumesAndVerifiesAndAnEditedFrameIsCaught=119
  Cube2.SeededMatchIsDeterministicAndConverts=101
  Slurm.ASignalledTaskRequeuesAndACancelledOneIsReportedAndRerun=95
  Slurm.DemoAsAChainOfJobsGivesTheLocalDemosTables=55
  Cube2.SecondMapsLavaAndWaterConvertValidateAndAgreeWithTheGame=55
  OpenArena.AnEmulatedMatchIsTheSameOnEveryHost=50
  Cube2.TheGamesOwnFramesAgreeWithTheDatasetsRenderOfThem=46
  Slurm.CaptureArrayOfSeedsMatchesLocalCaptures=40
  OpenArena.SeededMatchesOnTwoMapsAreByteIdentical=33
  OpenArena.MatchConvertsWithMorphTargetsWhereTheGamePutThem=30
  Cycles.RadianceAgreesWithDynbenchForEachKindOfLight=21)
foreach(entry IN LISTS dynbench_test_costs)
  string(REPLACE "=" ";" pair "${entry}")
  list(GET pair 0 name)
  list(GET pair 1 cost)
  set_tests_properties("${name}" PROPERTIES COST ${cost})
endforeach()
