"""Regenerate the suite tables in docs/suites.md from the suite files (run after editing a suite):

    .venv/bin/python scripts/suite_doc_tables.py

Each generated block sits between ``<!-- tables:NAME -->`` and ``<!-- /tables:NAME -->`` markers.
"""

import re
from pathlib import Path

import gift

DOC = Path(__file__).resolve().parents[1] / "docs" / "suites.md"
PAPER_OMEGA = {"water_sensitive": "ω1", "paper_based": "ω2", "art_supplies": "ω3a", "reading_material": "ω3b",
               "valuables": "ω4a", "electronics": "ω4b"}
DEV_LABEL = {"cloth_items": "d1a", "breakables": "d1b", "leather_goods": "d2a", "wooden_items": "d2b",
             "toiletries": "d3a", "sewing_supplies": "d3b", "baking_tools": "d4a", "gardening_supplies": "d4b"}
DEV2_LABEL = {"musical_instruments": "e1a", "houseplants": "e1b", "metal_things": "e2a", "toys": "e2b",
              "dog_things": "e3a", "fishing_tackle": "e3b", "hair_accessories": "e4a", "candles": "e4b"}
DEV3_LABEL = {"eyewear": "f1a", "timepieces": "f1b", "rubber_things": "f2a", "spices": "f2b",
              "swimming_kit": "f3a", "camping_gear": "f3b", "batteries": "f4a", "coins": "f4b"}
DEV4_LABEL = {"headwear": "g1a", "feathered_things": "g1b", "stone_things": "g2a", "fasteners": "g2b",
              "baby_things": "g3a", "gym_kit": "g3b", "keys": "g4a", "measuring_tools": "g4b"}
DEV5_LABEL = {"mirrored_things": "h1a", "chocolate": "h1b", "seashells": "h2a", "cordage": "h2b",
              "footwear": "h3a", "magic_props": "h3b", "cutlery": "h4a", "adhesives": "h4b"}
DEV6_LABEL = {"cheeses": "i1a", "bee_products": "i1b", "dried_flowers": "i2a", "smoking_things": "i2b",
              "alcoholic_drinks": "i3a", "cycling_kit": "i3b", "fire_lighting": "i4a", "openers": "i4b"}
DEV7_LABEL = {"citrus_fruit": "j1a", "awards": "j1b", "sugar": "j2a", "mushrooms": "j2b",
              "handwear": "j3a", "table_tennis": "j3b", "drinking_straws": "j4a", "table_mats": "j4b"}
DEV8_LABEL = {"vinyl_records": "k1a", "photographic_film": "k1b", "pasta": "k2a", "magnets": "k2b",
              "golf_kit": "k3a", "cricket_kit": "k3b", "neckwear": "k4a", "pest_control": "k4b"}
DEV9_LABEL = {"glow_in_the_dark": "l1a", "cured_meat": "l1b", "wheeled_things": "l2a", "seaweed": "l2b",
              "stargazing_kit": "l3a", "snooker_kit": "l3b", "earwear": "l4a", "flags": "l4b"}
DEV10_LABEL = {"eggs": "m1a", "doorstops": "m1b", "root_vegetables": "m2a", "coconut_things": "m2b",
               "ironing_kit": "m3a", "lawn_bowls_kit": "m3b", "hinged_things": "m4a", "bookends": "m4b"}
DEV11_LABEL = {"lampshades": "n1a", "tomato_things": "n1b", "squashes": "n2a", "cranked_things": "n2b",
               "rugby_kit": "n3a", "ice_skating_kit": "n3b", "aprons": "n4a", "suction_cup_things": "n4b"}
DEV12_LABEL = {"olives": "o1a", "fortune_telling": "o1b", "conifer_cones": "o2a", "trigger_things": "o2b",
               "ballet_kit": "o3a", "juggling_kit": "o3b", "tongs": "o4a", "drawstring_things": "o4b"}
DEV13_LABEL = {"fans": "p1a", "spouted_things": "p1b", "pulses": "p2a", "grinding_things": "p2b",
               "climbing_kit": "p3a", "poker_kit": "p3b", "socks": "p4a", "buckled_things": "p4b"}
DEV14_LABEL = {"cakes": "q1a", "bristled_things": "q1b", "flours": "q2a", "tasselled_things": "q2b",
               "orienteering_kit": "q3a", "chess_kit": "q3b", "sieves": "q4a", "stamping_things": "q4b"}
DEV15_LABEL = {"crackers": "r1a", "belled_things": "r1b", "rice": "r2a", "zipped_things": "r2b",
               "pony_grooming": "r3a", "tea_ceremony": "r3b", "spanners": "r4a", "gift_wrapping": "r4b"}
DEV16_LABEL = {"jam": "s1a", "plaster_things": "s1b", "laundry_detergent": "s2a", "hooded_things": "s2b",
               "archery_kit": "s3a", "soldering_kit": "s3b", "hammers": "s4a", "polishing_things": "s4b"}
DEV17_LABEL = {"stock": "t1a", "prayer_things": "t1b", "nightwear": "t2a", "dyeing_things": "t2b",
               "surfing_kit": "t3a", "tiling_kit": "t3b", "clamps": "t4a", "pocketed_things": "t4b"}
DEV18_LABEL = {"cooking_fats": "u1a", "chained_things": "u1b", "chopping_boards": "u2a", "polka_dot_things": "u2b",
               "athletics_kit": "u3a", "spinning_kit": "u3b", "underwear": "u4a", "correcting_things": "u4b"}
DEV19_LABEL = {"vinegars": "v1a", "sleeved_things": "v1b", "brassicas": "v2a", "embroidered_things": "v2b",
               "football_kit": "v3a", "mahjong_kit": "v3b", "plectrums": "v4a", "counting_things": "v4b"}
DEV20_LABEL = {"pears": "w1a", "laced_things": "w1b", "apples": "w2a", "felt_things": "w2b",
               "volleyball_kit": "w3a", "scrabble_kit": "w3b", "bottle_stoppers": "w4a", "tuning_things": "w4b"}
DEV21_LABEL = {"baskets": "x1a", "pleated_things": "x1b", "breakfast_cereals": "x2a", "plastic_things": "x2b",
               "fencing_kit": "x3a", "pottery_kit": "x3b", "puzzles": "x4a", "fluff_removers": "x4b"}
DEV22_LABEL = {"dresses": "y1a", "gilded_things": "y1b", "salad_leaves": "y2a", "velvet_things": "y2b",
               "monopoly_kit": "y3a", "bingo_kit": "y3b", "essential_oils": "y4a", "drain_clearers": "y4b"}
DEV23_LABEL = {"mangoes": "z1a", "lacquered_things": "z1b", "lunchboxes": "z2a", "copper_things": "z2b",
               "dnd_kit": "z3a", "cluedo_kit": "z3b", "fossils": "z4a", "drilling_things": "z4b"}
DEV24_LABEL = {"cherries": "a1a", "frog_shaped_things": "a1b", "pizzas": "a2a", "corduroy_things": "a2b",
               "netball_kit": "a3a", "trivial_pursuit_kit": "a3b", "meteorites": "a4a", "mexican_things": "a4b"}
DEV25_LABEL = {"figs": "b1a", "house_shaped_things": "b1b", "burgers": "b2a", "crocheted_things": "b2b",
               "pickleball_kit": "b3a", "catan_kit": "b3b", "butterflies": "b4a", "signalling_things": "b4b"}
DEV26_LABEL = {"salmon": "c1a", "pineapple_shaped_things": "c1b", "aubergines": "c2a", "hand_painted_things": "c2b",
               "hurling_kit": "c3a", "bridge_kit": "c3b", "sea_glass": "c4a", "practical_joke_things": "c4b"}
DEV27_LABEL = {"grapes": "α1a", "elephant_shaped_things": "α1b", "asparagus": "α2a", "hessian_things": "α2b",
               "croquet_kit": "α3a", "risk_kit": "α3b", "antlers": "α4a", "scottish_things": "α4b"}
DEV28_LABEL = {"blackberries": "β1a", "lighthouse_shaped_things": "β1b", "okra": "β2a", "terracotta_things": "β2b",
               "polo_kit": "β3a", "battleship_kit": "β3b", "skulls": "β4a", "almond_things": "β4b"}
DEV29_LABEL = {"rhubarb": "γ1a", "cactus_shaped_things": "γ1b", "melons": "γ2a", "raffia_things": "γ2b",
               "curling_kit": "γ3a", "carrom_kit": "γ3b", "birds_nests": "γ4a", "carob_things": "γ4b"}
DEV30_LABEL = {"peaches": "δ1a", "hedgehog_shaped_things": "δ1b", "doughnuts": "δ2a", "alpaca_things": "δ2b",
               "lacrosse_kit": "δ3a", "carcassonne_kit": "δ3b", "teeth": "δ4a", "cassava_things": "δ4b"}
DEV31_LABEL = {"raspberries": "ε1a", "penguin_shaped_things": "ε1b", "pancakes": "ε2a", "tweed_things": "ε2b",
               "kendo_kit": "ε3a", "pandemic_kit": "ε3b", "geodes": "ε4a", "peanut_things": "ε4b"}
DEV32_LABEL = {"dates": "ζ1a", "cat_shaped_things": "ζ1b", "dumplings": "ζ2a", "sheepskin_things": "ζ2b",
               "boxing_kit": "ζ3a", "wingspan_kit": "ζ3b", "crystals": "ζ4a", "hazelnut_things": "ζ4b"}
DEV33_LABEL = {"durians": "η1a", "turtle_shaped_things": "η1b", "prawns": "η2a", "tulle_things": "η2b",
               "scuba_kit": "η3a", "terraforming_mars_kit": "η3b", "amber": "η4a", "buckwheat_things": "η4b"}


def summary(suite, label: dict[str, str], column: str) -> str:
    rows = [f"| intent | {column} | task | train (relevant) | test (relevant) | S_R | S_lang | S_vis | S_unk |",
            "|---|---|---|---|---|---|---|---|---|"]
    for i in suite.intents:
        sizes = [len(i.subset(c)) for c in ("R", "lang", "vis", "unk")]
        rows.append(f"| `{i.id}` | {label[i.id]} | `{i.task}` | {len(i.train_objects)} ({len(i.relevant_train)}) | "
                    f"{len(i.test)} ({len(i.relevant_test)}) | " + " | ".join(str(x) if x else "–" for x in sizes)
                    + " |")
    return "\n".join(rows)


def intent_tables(suite, label: dict[str, str]) -> str:
    out = []
    for i in suite.intents:
        out.append(f"#### `{i.id}` — {label[i.id]}: *{i.text}* (task `{i.task}`)\n")
        rel = ", ".join(i.relevant_train)
        irr = ", ".join(o for o in i.train_objects if o not in i.relevant_train)
        out.append(f"Training objects: **relevant** {rel}; **irrelevant** {irr}.\n")
        out.append("| test object | relevant | subsets |\n|---|---|---|")
        for t in i.test:
            sub = ", ".join("S_" + c for c in t.confounds) if t.confounds else "S_R"
            out.append(f"| {t.object} | {'yes' if t.relevant else 'no'} | {sub} |")
        out.append("")
    return "\n".join(out)


def put(doc: str, name: str, body: str) -> str:
    pattern = re.compile(rf"(<!-- tables:{re.escape(name)} -->\n).*?(<!-- /tables:{re.escape(name)} -->)", re.DOTALL)
    if not pattern.search(doc):
        raise SystemExit(f"docs/suites.md has no <!-- tables:{name} --> block")
    return pattern.sub(lambda m: m.group(1) + body.rstrip("\n") + "\n" + m.group(2), doc, count=1)


def catalog_size(doc: str, name: str, n: int) -> str:
    """Set "its catalog holds N objects" in the section of suite ``name`` only."""
    head = f"## The `{name}` suite\n"
    if head not in doc:
        raise SystemExit(f"docs/suites.md has no section {head.strip()!r}")
    before, rest = doc.split(head, 1)
    section, sep, after = rest.partition("\n## ")
    section = re.sub(r"its catalog holds\s+\d+ objects", lambda m: re.sub(r"\d+", str(n), m.group(0)), section)
    return before + head + section + sep + after


#: Each development suite and its intents' labels, in the order of docs/suites.md.
DEV_SUITE_LABELS = {"gift-dev": DEV_LABEL, "gift-dev2": DEV2_LABEL, "gift-dev3": DEV3_LABEL, "gift-dev4": DEV4_LABEL,
                    "gift-dev5": DEV5_LABEL, "gift-dev6": DEV6_LABEL, "gift-dev7": DEV7_LABEL, "gift-dev8": DEV8_LABEL,
                    "gift-dev9": DEV9_LABEL, "gift-dev10": DEV10_LABEL, "gift-dev11": DEV11_LABEL,
                    "gift-dev12": DEV12_LABEL, "gift-dev13": DEV13_LABEL, "gift-dev14": DEV14_LABEL,
                    "gift-dev15": DEV15_LABEL, "gift-dev16": DEV16_LABEL, "gift-dev17": DEV17_LABEL,
                    "gift-dev18": DEV18_LABEL, "gift-dev19": DEV19_LABEL,
                    "gift-dev20": DEV20_LABEL, "gift-dev21": DEV21_LABEL, "gift-dev22": DEV22_LABEL,
                    "gift-dev23": DEV23_LABEL, "gift-dev24": DEV24_LABEL, "gift-dev25": DEV25_LABEL,
                    "gift-dev26": DEV26_LABEL, "gift-dev27": DEV27_LABEL,
                    "gift-dev28": DEV28_LABEL, "gift-dev29": DEV29_LABEL, "gift-dev30": DEV30_LABEL,
                    "gift-dev31": DEV31_LABEL, "gift-dev32": DEV32_LABEL, "gift-dev33": DEV33_LABEL}


def main() -> None:
    doc = DOC.read_text(encoding="utf-8")
    paper = gift.load_suite("gift-paper")
    devs = {name: gift.load_suite(name) for name in DEV_SUITE_LABELS}
    doc = put(doc, "gift-paper:summary", summary(paper, PAPER_OMEGA, "paper"))
    doc = put(doc, "gift-paper:intents", intent_tables(paper, PAPER_OMEGA))
    for name, label in DEV_SUITE_LABELS.items():
        doc = put(doc, f"{name}:summary", summary(devs[name], label, "label"))
        doc = put(doc, f"{name}:intents", intent_tables(devs[name], label))
    doc = re.sub(r"a catalog of \d+ objects", f"a catalog of {len(paper.objects)} objects", doc)
    for name, suite in devs.items():
        doc = catalog_size(doc, name, len(suite.objects))
    DOC.write_text(doc, encoding="utf-8")

if __name__ == "__main__":
    main()
