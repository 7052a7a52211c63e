"""Exchange with CAD (docs/exchange.md): a spec's motion as DXF curves and link skeletons
(:mod:`screwkit.exchange.dxf`) or an animated glTF scene (:mod:`screwkit.exchange.gltf`),
written by ``screwkit export``; :func:`screwkit.exchange.export.export_motion` chooses."""
