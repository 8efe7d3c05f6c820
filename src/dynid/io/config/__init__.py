"""The configs: TOML decoded into the part classes (identification, excitation, fleet manifests), their shared types,
the dataset specifications that say how a log is read, ``dynid init``'s starter config and ``dynid migrate``."""
