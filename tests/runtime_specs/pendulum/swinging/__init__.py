"""The functions of tests/runtime_specs/pendulum (docs/simulation.md, "Your own robot in MuJoCo")."""
