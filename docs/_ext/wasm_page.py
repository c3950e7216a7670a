"""A Sphinx extension: the files of the page that runs the FMU's wasm binary (docs/browser.md),
made during the build by the repository's build tool (fmu_build/wasm_page.py) into the site's
wasm/ folder.

The FMU is the checkout's FMI 3.0 one (pendulum_fmu.default_fmu(3), rebuilt when stale) unless
the build names another: ``sphinx-build -D wasm_page_fmu=path/to/Pendulum-fmi3.fmu ...``. Node 20
and npm are needed, and web/'s jco, which the build installs (``npm ci --prefix web``, from the
npm registry) where it is missing: without them the build stops, saying so in one line.
"""

from pathlib import Path

from sphinx.errors import ExtensionError


def write_wasm_page_files(app) -> None:
    """Transpile the FMU's wasm binary and copy the page's scripts into <outdir>/wasm/."""
    if app.builder.format != "html":
        return
    from fmu_build.wasm_page import write_page_files
    from pendulum_fmu import default_fmu
    from pendulum_fmu._errors import BuildError

    try:
        fmu = Path(app.config.wasm_page_fmu or default_fmu(3))
        write_page_files(fmu, Path(app.outdir) / "wasm")
    except BuildError as error:
        raise ExtensionError(f"the wasm page (docs/browser.md): {error}") from None


def setup(app):
    """Register the page's files with Sphinx (the extension's entry point)."""
    app.add_config_value("wasm_page_fmu", "", "html", types=[str])
    app.connect("builder-inited", write_wasm_page_files)
    return {"parallel_read_safe": True, "version": "1"}
