"""Fit from arrays, predict another log, print the parameters with σ, save, load back, export: the API in 10 lines."""

import dynid

robot = dynid.load_robot("er16")
log, other = dynid.simulated_log(robot, seconds=30, rng=1), dynid.simulated_log(robot, seconds=20, rng=2)
ident = dynid.Identifier(robot, estimators=["wls", "sdp"]).fit(log.t, log.q, log.tau)
print(ident.parameters("wls"))                                            # name, value, σ, unit
print(f"main estimate {ident.result_.main}; R² of its torques on another log: {ident.score(other):.4f}")
ident.save("er16_results.json")                                            # results.json, as dynid identify writes
model = dynid.load_results("er16_results.json")                            # read back: predict, validate, export
open("er16_identified.urdf", "w").write(model.urdf())                      # the physically consistent estimate
