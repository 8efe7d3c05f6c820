"""Where dynid's work runs: BLAS and thread pools on the machine's cores (:mod:`.threads`), a child process beside the
parent (:mod:`.processes`), a Dask cluster for the studies and the fleet (:mod:`.cluster`), and the optional extras a
command needs (:mod:`.extras`). The lowest layer: it imports no other part of dynid."""
