"""`mercmac sim FILE|RIG --web`: the C-170.PB box and the stage in the browser.

A live session (mercmac.web.live) runs the simulation against the wall clock; a local server
(mercmac.web.server) serves the page (mercmac/web/static: plain JavaScript, SVG and CSS,
shipped in the package, nothing from the network), streams the state and takes the page's
presses. Like the CLI, it is an application of the library: it reads sim and render, and
nothing below imports it.
"""
