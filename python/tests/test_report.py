"""report.html in a real browser: Debian's chromium, headless, driven by Selenium (chromium-driver)."""

import io
import shutil

import pytest

import obsgroup

webdriver = pytest.importorskip("selenium.webdriver", reason="needs Selenium (python3-selenium)")
if not (shutil.which("chromedriver") and (shutil.which("chromium") or shutil.which("chromium-browser"))):
    pytest.skip("needs chromium and chromium-driver", allow_module_level=True)

from selenium.webdriver.chrome.service import Service  # noqa: E402
from selenium.webdriver.common.by import By  # noqa: E402


@pytest.fixture(scope="module")
def run(data, tmp_path_factory):
    out = tmp_path_factory.mktemp("report") / "out"
    result = obsgroup.partition(data / "office_2d" / "office.clf", out)
    return out, result


@pytest.fixture(scope="module")
def browser():
    options = webdriver.ChromeOptions()
    for argument in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu",
                     "--window-size=1400,1000"):
        options.add_argument(argument)
    driver = webdriver.Chrome(service=Service(shutil.which("chromedriver")), options=options)
    yield driver
    driver.quit()


def distinct_colours(png):
    try:
        from PIL import Image
        image = Image.open(io.BytesIO(png)).convert("RGB")
        return len(set(image.getdata()))
    except ImportError:
        import matplotlib.image
        import numpy as np
        pixels = (matplotlib.image.imread(io.BytesIO(png), format="png")[:, :, :3] * 255).astype(np.uint8)
        return len(np.unique(pixels.reshape(-1, 3), axis=0))


def test_the_report_is_one_file_that_needs_no_network(run):
    out, _ = run
    page = (out / "report.html").read_text(encoding="utf-8")
    assert "<script src" not in page and "http://" not in page.replace("http://www.w3.org/2000/svg", "")
    assert "https://" not in page and "data:image/png;base64," in page  # the local-map pictures are inside


def test_the_report_renders_the_places_and_is_not_blank(run, browser):
    out, result = run
    browser.get((out / "report.html").as_uri())
    places = browser.find_elements(By.CSS_SELECTOR, "#map path.place")
    assert len(places) == len(result["groups"])
    assert all(p.size["width"] > 5 and p.size["height"] > 5 for p in places)
    assert len(browser.find_elements(By.CSS_SELECTOR, "#places tbody tr")) == len(result["groups"])
    assert browser.find_element(By.ID, "title").text.endswith("office.clf")
    assert distinct_colours(browser.get_screenshot_as_png()) > 20
    assert browser.get_log("browser") == [] if hasattr(browser, "get_log") else True  # no script error


def test_clicking_a_place_shows_its_panel(run, browser):
    out, result = run
    browser.get((out / "report.html").as_uri())
    g = 3
    place = browser.find_element(By.CSS_SELECTOR, f'#map path.place[data-group="{g}"]')
    place.click()
    panel = browser.find_element(By.ID, "panel")
    assert panel.find_element(By.TAG_NAME, "h2").text == f"Place {result['place_ids'][g]}"
    assert f"observations\n{len(result['groups'][g])}" in panel.text
    image = panel.find_element(By.TAG_NAME, "img")
    assert browser.execute_script("return arguments[0].complete && arguments[0].naturalWidth", image) > 100
    assert "sel" in place.get_attribute("class")
    assert browser.execute_script("return location.hash") == f"#place={result['place_ids'][g]}"
    # a neighbour's link selects the neighbour
    neighbour = panel.find_element(By.CSS_SELECTOR, "a.place-link")
    target = neighbour.text
    neighbour.click()
    assert browser.find_element(By.CSS_SELECTOR, "#panel h2").text == f"Place {target}"


def test_a_link_to_a_place_opens_on_it(run, browser):
    out, result = run
    browser.get((out / "report.html").as_uri() + "#place=5")
    assert browser.find_element(By.CSS_SELECTOR, "#panel h2").text == "Place 5"
    assert browser.find_element(By.CSS_SELECTOR, "#places tbody tr.sel td").text == "5"
