"""The imperative shell: connects the pure mission to a vehicle (``uavtool.link``) and a camera,
executes its commands, records everything (``uavtool fly``)."""
