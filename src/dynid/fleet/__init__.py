"""Many robots and service lives: fleet identification (:mod:`.identification`, on Dask), odd units
(:mod:`.outliers`), drift monitoring (:mod:`.monitor`) and its change detection (:mod:`.change_detection`)."""
