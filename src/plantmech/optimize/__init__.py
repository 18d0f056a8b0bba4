"""Automatic optimization of both mechanisms (problem definitions on the batch APIs,
pymoo algorithms, run records)."""

# the problem names, here so the command line can list them without importing numpy
PROBLEMS = ("seeder-layer1", "seeder-layer2", "seeder-layered", "seeder-joint", "transplanter",
            "planetary")
# the algorithms (``optimize.runner``), here for the same reason
ALGORITHMS = ("nsga2", "de", "cmaes")
