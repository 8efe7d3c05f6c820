"""The configs: TOML decoded into the part classes (identification, excitation, fleet manifests) and their shared
types, ``dynid init``'s starter config and ``dynid migrate``. A dataset's table is decoded into the log readers' own
spec (:mod:`dynid.io.logs.dataset_specs`)."""
