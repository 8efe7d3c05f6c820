"""dynid's own helpers, below every other layer: how the public API takes its settings (:mod:`.keywords`), typed
decoding of the configs (:mod:`.typed`), checks of the arrays a user gives (:mod:`.checks`), the on-disk column store
a long log is spooled to (:mod:`.column_store`), and each joint's Gram matrices of a block of rows (:mod:`.grams`)."""
