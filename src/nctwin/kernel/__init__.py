"""Virtual NC kernels: each is ``run(toolpath, machine) -> Motion``."""
