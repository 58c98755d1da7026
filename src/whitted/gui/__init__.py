"""The desktop scene editor (``whitted gui``): a PySide6 (Qt 6) thin client of the scene model
and the render API. Nothing here renders by itself: edits build new validated
:class:`whitted.Scene` snapshots and every picture comes from :class:`whitted.RenderJob`.

Modules, one idea each:

- ``document``: the edited scene, its file, selection and undo stack
- ``commands``: the undo command (a before/after pair of scene snapshots)
- ``catalog``: the ready-made objects and lights of the Add menus
- ``fields``: which properties each kind of item has, and how to edit them
- ``widgets``: the field editors (numbers, vectors, sliders, colours, files)
- ``properties``: the properties panel of the selected item
- ``tree``: the scene tree (camera, render settings, background, lights, objects)
- ``camera_ops``: orbit, pan, zoom and axis rotations of the camera (pure math)
- ``viewport``: the picture (fit, 1:1, zoom), clicks vs drags, keys, overlays
- ``picking``: the object-id image: what is under the pointer, the selection's outline
- ``transform_tool``: G/R/S moves, object bounds and centres
- ``icons``: the icons of item kinds, preset swatches
- ``messages``: refusals in the user's words
- ``system_check``: Qt's X11 libraries, checked before Qt starts
- ``render_controller``: full renders and the interactive preview on worker threads
- ``autosave``, ``recent``: nothing lost, files found again
- ``main_window``: the window that ties them together; ``app``: the entry point
"""
