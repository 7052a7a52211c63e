"""``screwkit studio``: a local web app where a dimension is dragged and the mechanism, its
curves and its loads are solved again and redrawn at once (docs/studio.md). The design and its
saving (:mod:`.design`), what a page draws (:mod:`.solve`), one tab's messages and history
(:mod:`.session`), the exports (:mod:`.exports`), the page (:mod:`.page`) and the server
(:mod:`.server`). Needs the ``studio`` extra (Starlette, uvicorn, websockets, tomlkit); the
notebook controls (:mod:`.notebook`) the ``notebook`` extra (ipywidgets)."""
