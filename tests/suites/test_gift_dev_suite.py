"""The shipped development suites ``gift-dev``, ``gift-dev2``, ``gift-dev3``, ``gift-dev4``, ``gift-dev5``,
``gift-dev6``, ``gift-dev7``, ``gift-dev8``, ``gift-dev9``, ``gift-dev10``, ``gift-dev11``, ``gift-dev12``,
``gift-dev13``, ``gift-dev14``, ``gift-dev15``, ``gift-dev16``, ``gift-dev17``, ``gift-dev18``, ``gift-dev19``,
``gift-dev20``, ``gift-dev21``, ``gift-dev22``, ``gift-dev23``, ``gift-dev24``, ``gift-dev25``, ``gift-dev26``,
``gift-dev27``, ``gift-dev28``, ``gift-dev29``, ``gift-dev30``, ``gift-dev31``, ``gift-dev32`` and ``gift-dev33``: new
intents and objects, none borrowed from the suites they are checked against.

Like ``test_gift_paper_suite.py`` these check the data (catalog, splits, subsets, look-alikes, the
document's tables); they also check by name that nothing is shared with ``gift-paper``, the LM test
suite or the other development suite. Placement on the robots is checked in
``tests/experiments/test_scene_placement.py``.
"""

from __future__ import annotations

import functools
import itertools
import re
from pathlib import Path

import pytest
from suite_checks import MAX_EXTENT_M, extent, labels, looks_alike, names_alike

import gift
from gift.core.data import slug
from gift.core.suite import CONFOUNDS
from gift.plugins.manager import get_manager

ROOT = Path(__file__).resolve().parents[2]
LM_DEV = str(ROOT / "tests" / "kernels" / "data" / "lm_dev_suite.yaml")
FAMILIES = {"place_mug", "sweep_spill", "pack_backpack", "store_drawer"}
#: Goal patterns of gift-paper and lm-dev, which no development goal may repeat.
PAPER_AND_LM_GOALS = r"art|read|valuab|electron|paper|water|sharp|picnic|food|first aid|medic"
#: Per development suite: its sibling intents and its goals' own words, which would hand a description-reading
#: kernel the labels (no description of the suite may use them, and no goal of the other suites may name them).
DEV_SUITES = {
    "gift-dev": {
        "siblings": [("cloth_items", "breakables"), ("leather_goods", "wooden_items"),
                     ("toiletries", "sewing_supplies"), ("baking_tools", "gardening_supplies")],
        "label_words": r"fabric|cloth|textile|fragil|breakab|leather|\bwood|toiletr|sewing|baking|garden",
    },
    "gift-dev2": {
        "siblings": [("musical_instruments", "houseplants"), ("metal_things", "toys"),
                     ("dog_things", "fishing_tackle"), ("hair_accessories", "candles")],
        "label_words": r"instrument|music|plant|metal|\btoy|plaything|\bdog|canine|puppy|fish|tackle"
                       r"|\bangl(?:er|ing)|accessor|candle",
    },
    "gift-dev3": {
        "siblings": [("eyewear", "timepieces"), ("rubber_things", "spices"),
                     ("swimming_kit", "camping_gear"), ("batteries", "coins")],
        "label_words": r"eyewear|\bglasses|spectacle|goggle|\blens|sunglass|clock|\bwatch|timepiece|\btime\b"
                       r"|rubber|latex|spice|season|swim|\bpool|bathing|\bcamp|\btent\b|batter|\bvolt"
                       r"|coin|currency|money|cash|penny|pence|\bcents?\b",
    },
    "gift-dev4": {
        "siblings": [("headwear", "feathered_things"), ("stone_things", "fasteners"),
                     ("baby_things", "gym_kit"), ("keys", "measuring_tools")],
        "label_words": r"\bhats?\b|\bcaps?\b|headwear|headgear|millin|feather|plum(?:e|age)|\bquills?\b"
                       r"|stone|\brocks?\b|granite|marble|fasten|screw|\bnuts?\b|\bbolts?\b"
                       r"|\bbab(?:y|ies)|infant|newborn|toddler|\bgym|workout|exercis|fitness|cardio|\bweights?\b|\blift(?:ing)?\b|dumbbell|barbell"
                       r"|\bkeys?\b|keyring|keychain|keyhole|\blocks?\b|\bunlock|locksmith|measur|\bgauges?\b|calibrat",
    },
    "gift-dev5": {
        "siblings": [("mirrored_things", "chocolate"), ("seashells", "cordage"),
                     ("footwear", "magic_props"), ("cutlery", "adhesives")],
        "label_words": r"mirror|reflect|looking.glass|chocolat|cacao|shell|mollus|\bclams?\b|oyster|nacre|mother.of.pearl"
                       r"|\bstrings?\b|\bcords?\b|cordage|\bropes?\b|twine"
                       r"|footwear|\bshoes?\b|\bboots?\b|slipper|sandal|sneaker|\btrainers?\b"
                       r"|magic|magician|conjur|illusion|\btricks?\b|\bprops?\b"
                       r"|cutlery|silverware|flatware|utensil|\bforks?\b|\bspoons?\b|\bknife|\bknives"
                       r"|adhesi|\bglues?\b|\bgluing\b|\bsticky\b|\bsticking\b|\btapes?\b|\bpastes?\b",
    },
    "gift-dev6": {
        "siblings": [("cheeses", "bee_products"), ("dried_flowers", "smoking_things"),
                     ("alcoholic_drinks", "cycling_kit"), ("fire_lighting", "openers")],
        "label_words": r"chees|\bcurds?\b|dairy|\bbees?\b|honey|beeswax|\bhives?\b|apiar|apicult"
                       r"|flower|floral|\bblooms?\b|blossom|petal|bouquet|\bposy|\bposies"
                       r"|smok|tobacc|cigar|\bpipes?\b|nicotin"
                       r"|alcohol|booze|boozy|\bbeers?\b|\bwines?\b|\bspirits?\b|liquor|liqueur|\blagers?\b|\bales?\b"
                       r"|whiske?y|whiskies|vodka|\bgin\b|\brum\b|brandy"
                       r"|\bbikes?\b|bicycl|cycl|\brid(?:e|es|ing)\b|\bpedal"
                       r"|\bmatch(?:es|box|book|sticks?)?\b|\blighters?\b|\bfires?\b|firelight|\bflames?\b"
                       r"|\bignit|\bkindl|\btinder\b|\bopen|uncork",
    },
    "gift-dev7": {
        "siblings": [("citrus_fruit", "awards"), ("sugar", "mushrooms"),
                     ("handwear", "table_tennis"), ("drinking_straws", "table_mats")],
        "label_words": r"citrus|citric|\bfruits?\b|lemon|\blimes?\b|\boranges?\b"
                       r"|\bmedal|troph|\baward|\bprize"
                       r"|\bsugar|sucrose|\bsweeten|mushroom|\bfung(?:us|i|al)\b|toadstool|\bmycel"
                       r"|\bglov|mitten|\bmitts?\b|handwear|tennis|ping.?pong"
                       r"|\bstraws?\b|drinking|\bsip(?:s|ped|ping)?\b|coaster|placemat|\bmats?\b",
    },
    "gift-dev8": {
        "siblings": [("vinyl_records", "photographic_film"), ("pasta", "magnets"),
                     ("golf_kit", "cricket_kit"), ("neckwear", "pest_control")],
        "label_words": r"\bvinyl|\brecords?\b|\blps?\b|\balbums?\b|gramophone|phonograph"
                       r"|\bfilms?\b|photograph|\bphotos?\b|\bnegatives?\b"
                       r"|\bpasta\b|spaghetti|macaroni|\bmagnet"
                       r"|\bgolf|cricket"
                       r"|\bties?\b|necktie|neckwear|\bscar(?:f|fs|ves)\b|cravat"
                       r"|\bpests?\b|pesticid|insecticid|vermin",
    },
    "gift-dev9": {
        "siblings": [("glow_in_the_dark", "cured_meat"), ("wheeled_things", "seaweed"),
                     ("stargazing_kit", "snooker_kit"), ("earwear", "flags")],
        "label_words": r"\bglow|\bdark\b|\blumin|phosphor"
                       r"|\bcured\b|\bcuring\b|\bmeats?\b|salami|\bhams?\b|charcut|jerky|prosciutto"
                       r"|\bwheel|\bcast[oe]rs?\b|seaweed|\bkelp\b|\balga|\bnori\b"
                       r"|stargaz|\bstars?\b|\bstarry\b|astronom|telescop|constellat|\bplanets?\b|\bsky\b"
                       r"|snooker|billiard|\bcues?\b|\bbaize\b"
                       r"|\bears?\b|\bear(?:rings?|plugs?|buds?|pieces?|phones?)\b|\bhearing\b"
                       r"|\bflags?\b|\bbanners?\b|\bensigns?\b|\bpennants?\b",
    },
    "gift-dev10": {
        "siblings": [("eggs", "doorstops"), ("root_vegetables", "coconut_things"),
                     ("ironing_kit", "lawn_bowls_kit"), ("hinged_things", "bookends")],
        "label_words": r"\beggs?\b|eggshell|\byolks?\b|albumen"
                       r"|doorstop|\bdoors?\b|\bwedges?\b"
                       r"|\broots?\b|vegetabl|\bveg\b|\bveggies\b|carrot|parsnip|\bbeet|turnip|\bswedes?\b|radish"
                       r"|potato|celeriac|salsify|\bmooli\b|coconut|\bcocos?\b|\bcoir\b|\bcopra\b|\bbuko\b"
                       r"|\biron(?:s|ed|ing)?\b|\bcreas(?:e|es|ed|ing)\b|\bwrinkl"
                       r"|\bbowls?\b|\blawn\b|\bjacks?\b|\bbowling\b|\bbowlers?\b"
                       r"|\bhinge|\bbook|\bends?\b",
    },
    "gift-dev11": {
        "siblings": [("lampshades", "tomato_things"), ("squashes", "cranked_things"),
                     ("rugby_kit", "ice_skating_kit"), ("aprons", "suction_cup_things")],
        "label_words": r"lampshade|\bshades?\b|\blamps?\b"
                       r"|tomato|passata|ketchup|gazpacho|pomodoro|\bsugo\b"
                       r"|squash|pumpkin|courgette|zucchin|\bmarrows?\b|\bgourds?\b|cucurbit|kabocha|patty.?pan"
                       r"|butternut|\bcrank"
                       r"|rugby|\bscrums?\b|\bline-?out"
                       r"|\bskat|\bice\b|\brinks?\b"
                       r"|\baprons?\b|\bpinn(?:y|ies)\b|\bpinafores?\b|tablier|maekake"
                       r"|suction|\bsuckers?\b|\bplungers?\b",
    },
    "gift-dev12": {
        "siblings": [("olives", "fortune_telling"), ("conifer_cones", "trigger_things"),
                     ("ballet_kit", "juggling_kit"), ("tongs", "drawstring_things")],
        "label_words": r"\bolives?\b|kalamata|castelvetrano|gordal"
                       r"|fortun|\btarot|divinat|\bdiviners?\b|clairvoy|psychic|soothsay|\bseers?\b|\boracles?\b"
                       r"|prophe|palmist|\bscry|lenormand|\brunes?\b|crystal.?balls?"
                       r"|\bcones?\b|conifer|\bpines?\b|\bfirs?\b|spruce|larch|cedar|cypress|sequoia|redwood"
                       r"|trigger|\bguns?\b|pistol"
                       r"|ballet|ballerin|\bpointe\b|\btutus?\b|leotard|\bbarre\b|\bclass"
                       r"|juggl|diabolo|\bpoi\b|devil.?sticks?|circus"
                       r"|\btongs?\b"
                       r"|drawstring|draw-?cords?|\bdraw(?:s|n|ing)?\b",
    },
    "gift-dev13": {
        "siblings": [("fans", "spouted_things"), ("pulses", "grinding_things"),
                     ("climbing_kit", "poker_kit"), ("socks", "buckled_things")],
        "label_words": r"\bfans?\b|uchiwa|abanico|\bbris[eé]"
                       r"|\bspouts?\b|spouted|\bneti\b|dallah|porr[oó]n|\bsippy"
                       r"|\bpulses?\b|lentil|\bbeans?\b|legum|\bdh?aa?l\b|chickpea|garbanzo|borlotti"
                       r"|grind|\bground\b|\bmill(?:s|ed|ing)?\b|mortar|pestle|suribachi|molcajete|\bcrush|pulveri"
                       r"|climb|belay|boulder|\bcrags?\b|abseil|rappel|harness|carabin|karabin|quickdraw|descender"
                       r"|mountaineer"
                       r"|poker|casino|gambl|hold.?em|\bdeal(?:er|ers|ing)?\b|shuffl|\bchips?\b|\bbets?\b|betting|wager"
                       r"|\bsocks?\b|hosiery|argyle|footlet|\btabi\b"
                       r"|buckl",
    },
    "gift-dev14": {
        "siblings": [("cakes", "bristled_things"), ("flours", "tasselled_things"),
                     ("orienteering_kit", "chess_kit"), ("sieves", "stamping_things")],
        "label_words": r"\bcakes?\b|cupcake|g[aâ]teau|\bsponges?\b|madeleine|lamington|battenberg"
                       r"|bristl|\bbrush|\bbrooms?\b|besom|kabuki|mascara|dauber"
                       r"|\bflours?\b|\batta\b|besan|harina"
                       r"|tassel"
                       r"|orienteer|\bcompass|sportident|dibber"
                       r"|\bchess|checkmate|staunton"
                       r"|\bsieves?\b|\bsift|strainer|\bstrain(?:s|ed|ing)?\b|colander|chinois|tamis"
                       r"|\bstamp|\bseal(?:s|ed|ing)?\b|hanko|emboss|signet",
    },
    "gift-dev15": {
        "siblings": [("crackers", "belled_things"), ("rice", "zipped_things"),
                     ("pony_grooming", "tea_ceremony"), ("spanners", "gift_wrapping")],
        "label_words": r"cracker|matzo|senbei|hardtack|water.?biscuit"
                       r"|\bbells?\b|\bbelled\b|jingl|ghungr"
                       r"|\brice\b|basmati|arborio|carnaroli|\bbomba\b|koshihikari|camargue|risott|paella|sushi"
                       r"|\bzip"
                       r"|\bgroom|\bpon(?:y|ies)\b|\bhorse|equine|equestr|\bhoo(?:f|fs|ves)\b|\bmanes?\b|curry.?comb"
                       r"|ceremon|chanoyu|\bchad[oō]\b|chasen|chashaku|chawan|fukusa|kaishi|kensui|\braku\b"
                       r"|spanner|wrench|stillson|ratchet|\bsockets?\b|wheel.?brace"
                       r"|\bwrap|\bgifts?\b|\bpresents?\b|furoshiki",
    },
    "gift-dev16": {
        "siblings": [("jam", "plaster_things"), ("laundry_detergent", "hooded_things"),
                     ("archery_kit", "soldering_kit"), ("hammers", "polishing_things")],
        "label_words": r"\bjams?\b|preserves?\b|confitur|marmalad|conserves?\b"
                       r"|plaster|gypsum|chalkware|stucco"
                       r"|laundry|detergent|washing.?(?:powder|liquid)|soap.?(?:flakes|nuts)"
                       r"|\bhoods?\b|hooded|hoodie|anorak|cagoule|duffle"
                       r"|archer|\bbows?\b|bowstring|\barrows?\b|quiver|fletch|\bnocks?\b|\btargets?\b|bracer"
                       r"|solder|\bflux\b|\btinn(?:er|ing)\b"
                       r"|hammer|mallet|gavel"
                       r"|polish|\bbuff(?:s|ed|ing|er|ers)?\b|burnish",
    },
    "gift-dev17": {
        "siblings": [("stock", "prayer_things"), ("nightwear", "dyeing_things"),
                     ("surfing_kit", "tiling_kit"), ("clamps", "pocketed_things")],
        "label_words": r"\bstocks?\b|bouillon|\bbroths?\b|consomm|\bdashi\b|\boxo\b"
                       r"|\bpray|rosar|\bmalas?\b|tasbih|misbaha|komboskini|tallit|tefillin|worship|devotion"
                       r"|pyjama|pajama|\bpjs?\b|nightwear|sleepwear|nightdress|nightie|nightgown|nightshirt|negligee"
                       r"|jim.?jams"
                       r"|\bdy(?:e|es|ed|eing|er|ers)\b|dyestuff|mordant|\bhenna\b|indigo|\bwoad\b|madder|cochineal"
                       r"|\bsurf(?:s|er|ers|ing|board|boards)?\b|\bwaves?\b|wetsuit"
                       r"|\btil(?:e|es|ed|er|ers|ing)\b|grout|thinset|mosaic"
                       r"|\bclamp|\bcramps?\b|\bvices?\b|\bvises?\b|handscrew"
                       r"|\bpocket",
    },
    "gift-dev18": {
        "siblings": [("cooking_fats", "chained_things"), ("chopping_boards", "polka_dot_things"),
                     ("athletics_kit", "spinning_kit"), ("underwear", "correcting_things")],
        "label_words": r"\blard\b|dripping|\bfats?\b|\bsuet\b|\bghee\b|shortening|schmaltz|tallow|cookeen|\btrex\b"
                       r"|\bchain"
                       r"|\bchop|\bboards?\b|manaita|butcher.?s.?block"
                       r"|polka|\bdots?\b|dotted|dotty|\bspots?\b|spotted|spotty"
                       r"|athlet|\btrack\b|\brelay|\bsprint|discus|shot.?put|javelin|hurdl|\bspikes?\b|\bspiked\b"
                       r"|\bolympi"
                       r"|\bspin(?:s|ning|ner|ners|dle|dles)?\b|\byarns?\b|roving|\bcard(?:er|ers|ing)\b|niddy"
                       r"|lazy.?kate|\bdistaff"
                       r"|underwear|undergarment|underclothes|lingerie|knickers|\bbriefs?\b|\bboxers?\b|\bbras?\b"
                       r"|\bvests?\b|long.?johns|y.?fronts|\bpants\b|\bsmalls\b|\bundies\b"
                       r"|\beras|correct|tipp.?ex|snopake|\brub(?:bing)? out\b|mistak|white.?out",
    },
    "gift-dev19": {
        "siblings": [("vinegars", "sleeved_things"), ("brassicas", "embroidered_things"),
                     ("football_kit", "mahjong_kit"), ("plectrums", "counting_things")],
        "label_words": r"vinegar|balsam|\baceto\b|kurozu|sarson|\bacetic|vinaigr"
                       r"|sleeve"
                       r"|brassic|cabbage|broccol|cauliflower|brussels|\bsprouts?\b|\bkale\b|kohlrabi|romanesco"
                       r"|pak.?cho[iy]|bok.?cho[iy]|\bsavoy\b|cavolo|collard|calabrese|crucifer"
                       r"|embroider|needlework|needlepoint|cross.?stitch|crewel|sampler|suzani|sashiko|otomi|tenango"
                       r"|football|soccer|\bgoal|\bfooty\b|\bfifa\b|\bpitch(?:es)?\b|shin.?(?:pad|guard)|\bstuds?\b"
                       r"|\bstudded\b|\bcleats?\b|\bmundial"
                       r"|mah.?jon?gg?|\briichi\b|tenb[oō]|\bnmjl\b|\bpungs?\b|\bkongs?\b|\bchows?\b"
                       r"|plectr|\bpicks?\b|mizrab|\bbachi\b|\btsume\b"
                       r"|\bcount(?:s|ed|ing|ers?)?\b|\btally|abacus|abaci\b|soroban|schoty|suanpan|reckon"
                       r"|\btot(?:s|ted|ting)? up\b",
    },
    "gift-dev20": {
        "siblings": [("pears", "laced_things"), ("apples", "felt_things"),
                     ("volleyball_kit", "scrabble_kit"), ("bottle_stoppers", "tuning_things")],
        "label_words": r"\bpears?\b|conference|comice|concorde|williams|anjou|\bnashi\b|\bbosc\b|packham"
                       r"|\blac(?:e|es|ed|ing)\b|lace.?up|shoelace|\baglets?\b|eyelet"
                       r"|\bapples?\b|pippin|\brusset\b|bramley|braeburn|granny smith|pink lady|honeycrisp"
                       r"|golden delicious|\bfelt(?:ed|s)?\b|homburg|valenki|shyrdak"
                       r"|volley|\blibero|mikasa"
                       r"|scrabble|protiles?|tile.?tracking"
                       r"|stopper|\bbungs?\b|\bcorks?\b|vacu.?vin|grolsch|flip.?top|decanter top"
                       r"|\btun(?:e|es|ed|er|ers|ing)\b|pitch.?pipe|\bsnark\b|\ba440\b|drum.?key",
    },
    "gift-dev21": {
        "siblings": [("baskets", "pleated_things"), ("breakfast_cereals", "plastic_things"),
                     ("fencing_kit", "pottery_kit"), ("puzzles", "fluff_removers")],
        "label_words": r"basket|\bhampers?\b|wicker|\bcreels?\b|banneton|\btrugs?\b|pannier"
                       r"|\bpleat|pliss[eé]|\bkilts?\b|concertina|accordion|\btoques?\b|\bruffs?\b"
                       r"|cereal|muesli|granola|porridge|cornflake|\bbran\b|weetabix|cheerios|\balpen\b|breakfast"
                       r"|plastic|\bpolymer|perspex|bakelite"
                       r"|\bfenc|\bfoils?\b|[eé]p[eé]e|\bsabres?\b|\bsabers?\b|plastron|\blam[eé]\b"
                       r"|potter|\bkilns?\b|\bthrow(?:n|ing)? pots?\b|ceramicist"
                       r"|puzzl|jigsaw|tangram|\bsoma\b|hanoi|brain.?teas|\bmazes?\b"
                       r"|\bfluff|\blint\b|\bfuzz|\bbobbl|\bpill(?:s|ing|ed)?\b|gleener|\bde-?fuzz|\bde-?pill",
    },
    "gift-dev22": {
        "siblings": [("dresses", "gilded_things"), ("salad_leaves", "velvet_things"),
                     ("monopoly_kit", "bingo_kit"), ("essential_oils", "drain_clearers")],
        "label_words": r"\bdress|\bgowns?\b|\bfrocks?\b|sundress|cheongsam|qipao|dirndl|gymslip|shirtwaister"
                       r"|\bgild|\bgilt|gold.?leaf|ormolu|vermeil"
                       r"|salad|lettuce|\bleaves\b|\bleafy|\bgreens\b|spinach|radicchio|fris[eé]e|endive|chicory"
                       r"|\bm[aâ]che\b|little gems?|\bcos\b|romaine|iceberg|rocket|watercress"
                       r"|velvet|velour|velveteen"
                       r"|monopol|community chest|mayfair|free parking|title deed|hasbro"
                       r"|bingo|housey|housie|tambola|tombola|\bdabb?ers?\b|\bdaubers?\b|\blotto\b"
                       r"|essential|\boils?\b|aromatherap|neroli|ylang|patchouli"
                       r"|\bdrains?\b|unblock|unclog|\bblocked\b|\bplung|caustic|drano|zip.?it\b|\bplumb",
    },
    "gift-dev23": {
        "siblings": [("mangoes", "lacquered_things"), ("lunchboxes", "copper_things"),
                     ("dnd_kit", "cluedo_kit"), ("fossils", "drilling_things")],
        "label_words": r"mango|alphonso|ataulfo|kesar|chaunsa|carabao|tommy atkins|\bkent\b|keitt|haden"
                       r"|lacquer|japann|urushi|cinnabar|shellac|maki-?e\b|\binros?\b|\blac\b"
                       r"|lunch|bento|tiffin|\bdabbas?\b|snap tins?|crib tins?"
                       r"|copper|\bcupr|cezve|ibrik|cataplana|moscow mule|verdigris"
                       r"|dungeon|dragon|\bd ?& ?d\b|\bdnd\b|role.?play|\brpgs?\b|beholder|xanathar|monster manual"
                       r"|player'?s handbook|wizards of the coast"
                       r"|cluedo|\bclue\b|whodunn?it|colonel mustard|professor plum|reverend green|miss scarlett?"
                       r"|mrs\.? peacock|mrs\.? white|dr\.? black|lead pip"
                       r"|fossil|ammonite|trilobite|belemnite|petrif|pal(?:a|ae|e)ontolog|crinoid"
                       r"|\bdrill|\bbor(?:e|es|ed|ing)\b|\bbits?\b|gimlet|\bbrace\b|auger|forstner|countersink"
                       r"|pin vi[cs]e|archimedes",
    },
    "gift-dev24": {
        "siblings": [("cherries", "frog_shaped_things"), ("pizzas", "corduroy_things"),
                     ("netball_kit", "trivial_pursuit_kit"), ("meteorites", "mexican_things")],
        "label_words": r"cherr|morello|rainier|\bbings?\b|montmorency|amarena|griott|maraschino|kirsch|\blapins\b"
                       r"|\bfrog|\btoads?\b|amphibi|tadpole|croak|ribbit|kermit|keroppi|greninja|jeremy fisher"
                       r"|pizz|margherita|quattro stagioni|calzone"
                       r"|corduroy|needlecord|jumbo.?cord|elephant.?cord|\bcords\b|\bwales?\b|\bwaled\b|pinwale"
                       r"|netball|netburner|goal shooter|goal attack|goal defen[cs]e|goal keeper|wing attack"
                       r"|wing defen[cs]e"
                       r"|trivial|pursuit|\bgenus\b|baby boomer"
                       r"|meteor|campo del cielo|gibeon|sikhote|chondrit|pallasit|widmanst|shooting stars?"
                       r"|space rocks?|asteroid|\bbolides?\b"
                       r"|mexic|m[eé]xico",
    },
    "gift-dev25": {
        "siblings": [("figs", "house_shaped_things"), ("burgers", "crocheted_things"),
                     ("pickleball_kit", "catan_kit"), ("butterflies", "signalling_things")],
        "label_words": r"\bfigs?\b|ficus|brown turkeys?|black missions?|kadota|panach[eé]e|calimyrna|smyrna|\bbursa\b"
                       r"|\bhous(?:e|es|ing)\b|\bcottages?\b|\bchalets?\b|\bhomes?\b|bungalow|\bcabins?\b|\bhuts?\b"
                       r"|lilliput lane|cuckoo|nest.?box"
                       r"|burger|\bpatt(?:y|ies)\b|big mac|whopper|quarter.?pounder|\bsliders?\b|hamburg"
                       r"|crochet|amigurumi|granny.?squares?|\bafghans?\b|tunisian|\bfilet\b|tawashi"
                       r"|pickle|\bdinks?\b|selkirk|franklin x-?40|dura fast|\bonix\b|joola"
                       r"|catan|settlers?\b|seafarers|longest road|largest army|teuber"
                       r"|butterfl|lepidopter|morpho|red admirals?|\bpeacocks?\b|painted lad(?:y|ies)|swallowtail"
                       r"|birdwing|monarch|brimstone|tortoiseshell|fritillar|papilio"
                       r"|signal|\bsos\b|mayday|distress|semaphore|\bmorse\b|heliograph|aldis|thunderer|\bbeacons?\b"
                       r"|\bflares?\b|\bwhistl",
    },
    "gift-dev26": {
        "siblings": [("salmon", "pineapple_shaped_things"), ("aubergines", "hand_painted_things"),
                     ("hurling_kit", "bridge_kit"), ("sea_glass", "practical_joke_things")],
        "label_words": r"salmon|sockeye|\bcoho\b|chinook|\bketa\b|gravad|gravlax|\blox\b|\bgrilse\b|\bsmolts?\b"
                       r"|pineapple|\bananas\b|\bpi[nñ]as?\b|bromeliad|spongebob"
                       r"|aubergin|eggplant|brinjal|melanzan|baingan|listada|rosa bianca|black beaut|moussaka"
                       r"|baba.?g[hn]a?noush"
                       r"|\bpaint|hand-?decorat|\bbrush|rosemal|zhostovo|khokhlom|bargeware|roses and castles|\btole\b"
                       r"|watercolou?r|gouache|\bacrylics?\b"
                       r"|hurl|sliotar|\bcam[aá]ns?\b|camogie|\bgaa\b|mycro|\bbas\b|\bbos\b|croke park|all-ireland"
                       r"|\bpuck"
                       r"|\bbridge|bidding|\bbids?\b|\bacol\b|duplicate|convention cards?|stayman|blackwood|\bdummy\b"
                       r"|vulnerab|\bslams?\b|\btrumps?\b"
                       r"|sea.?glass|beach.?glass|mermaid|seaham|\bmultis?\b|\bsea\b|\bbeach|\bshores?\b|tideline"
                       r"|\bcoast(?:s|al)?\b"
                       r"|practical jok|\bjok(?:e|es|er|ers|ing|ey)\b|prank|\bgags?\b|\bhoax|\bfool(?:s|ed|ing)?\b"
                       r"|whoopee"
                       r"|\bbuzzers?\b|dribble glass|black.?eye|stink.?bomb|itching powder|sneezing powder|\btricks?\b"
                       r"|\bjapes?\b",
    },
    "gift-dev27": {
        "siblings": [("grapes", "elephant_shaped_things"), ("asparagus", "hessian_things"),
                     ("croquet_kit", "risk_kit"), ("antlers", "scottish_things")],
        "label_words": r"\bgrapes?\b|grapevine|\bvines?\b|vineyard|\bvitis\b|thompson seedless|crimson seedless|muscat"
                       r"|moscato|concord|sultana|raisin"
                       r"|elephant|\bdumbo\b|\bbabar\b|\belmer\b|\bjumbo\b|heffalump|pachyderm|\btrunks?\b|\btusks?\b"
                       r"|\bivory\b|ganesh"
                       r"|asparag|\bsprue\b|spargel|argenteuil|violetto|albenga|\bspears?\b"
                       r"|hessian|burlap|gunny|\bjute\b|sackcloth|\bsacking\b"
                       r"|croquet|\broquet|deadness|\bjaques\b|\bwickets?\b"
                       r"|\brisk|hasbro|parker brothers|kamchatka|irkutsk|yakutsk|world (?:conquest|domination)"
                       r"|antler|\bsheds?\b|\btines?\b|\bstags?\b|\bdeer\b|reindeer|\bmoose\b|\belks?\b|caribou|\broe\b"
                       r"|\bfallow\b|\bwapiti\b|\bsika\b|\bcast\b"
                       r"|scot|caledonia|\bhighlands?\b|\bhebrid|glasgow|edinburgh|aberdeen|dundee|inverness|\bharris\b"
                       r"|shetland|orkney|thistle|tartan|saltire|\bloch\b|\bclans?\b|irn-?bru|tunnock|\bquaich|sporran"
                       r"|\bkilts?\b|\bceilidh|\bbagpipe|\bpipers?\b",
    },
    "gift-dev28": {
        "siblings": [("blackberries", "lighthouse_shaped_things"), ("okra", "terracotta_things"),
                     ("polo_kit", "battleship_kit"), ("skulls", "almond_things")],
        "label_words": r"blackberr|\bbrambles?\b|marionberr|chester thornless|\brubus\b|dewberr|boysenberr|loganberr"
                       r"|tayberr"
                       r"|lighthouse|\bpharos\b|smeaton|eddystone|hatteras|fastnet|\bbeacons?\b|lightship"
                       r"|\bokra|\bbhindi|\bgombo|\bgumbo|lad(?:y|ies)'?s?.?fingers?|abelmoschus|\bbamy?ia\b|quiabo"
                       r"|terra.?cotta|\bclay|earthenware|\bcazuelas?\b|\bdiyas?\b|impruneta"
                       r"|\bpolo\b|\bchukk|hurlingham|\bhpa\b|polocrosse"
                       r"|battleship|milton bradley|\bsalvo\b|you sank"
                       r"|skull|\bcrani|braincase"
                       r"|almond|marzipan|frangipane|orgeat|calisson|turr[oó]n|\bjijona|amarett|mandorl|persipan"
                       r"|amandine",
    },
    "gift-dev29": {
        "siblings": [("rhubarb", "cactus_shaped_things"), ("melons", "raffia_things"),
                     ("curling_kit", "carrom_kit"), ("birds_nests", "carob_things")],
        "label_words": r"rhubarb|\brheum\b|pie.?plant|timperley|\bvictoria\b|roobarb"
                       r"|cact|saguaro|opuntia|prickly.?pear|golden.?barrel|organ.?pipe|cholla|cereus"
                       r"|melon|cantaloup|honeydew|charentais|\bgalia\b|piel de sapo|\bogen\b|cucumis|citrullus"
                       r"|raffia|raphia|rofia|\bkuba\b|\bdida\b|shoowa|rabane"
                       r"|curl|bonspiel|\bwcf\b|little rock"
                       r"|carr?om\b|carroms?|\bstriker|\bqueen\b|\bicf\b"
                       r"|\bnests?\b|nesting|nestl|eyrie|\bdrey"
                       r"|carob|ceratonia|locust bean|st\.? john's bread|kharroub|harnup|pasteli|algarrob",
    },
    "gift-dev30": {
        "siblings": [("peaches", "hedgehog_shaped_things"), ("doughnuts", "alpaca_things"),
                     ("lacrosse_kit", "carcassonne_kit"), ("teeth", "cassava_things")],
        "label_words": r"peach|nectarin|prunus|persica|redhaven|elberta|paraguayo|p[eê]ches?\b|melocot"
                       r"|hedgehog|hedgepig|erinace|tiggy|pricklepants|\burchins?\b|\bsonic\b"
                       r"|dough.?nut|\bdonuts?\b|bombolon|sufgani|p[aą]czk|berliner|krapfen|malasada|loukoumad"
                       r"|alpaca|\bsuri\b|huacaya|\bpaco\b|chullo"
                       r"|lacrosse|\bcrosse|la ?crosse|lacroix|nocsae|\bncaa\b"
                       r"|carcassonne|meeple|\bfollowers?\b|wrede"
                       r"|teeth|tooth|\btusks?\b|\bmolars?\b|\bincisors?\b|\bfangs?\b"
                       r"|\bdent(?:al|ine|ition)|\bcanines?\b"
                       r"|cassava|manioc|mandioca|\byuca\b|tapioca|\bgarri\b|\bgari\b|farofa|cassareep|cassis|cassata",
    },
    "gift-dev31": {
        "siblings": [("raspberries", "penguin_shaped_things"), ("pancakes", "tweed_things"),
                     ("kendo_kit", "pandemic_kit"), ("geodes", "peanut_things")],
        "label_words": r"raspberr|framboise|\brubus\b|idaeus|tulameen|glen ample|autumn bliss"
                       r"|penguin|\bpingu\b|\btux\b|mcgraw|spheniscus|aptenodytes"
                       r"|pancak|\bcr[eê]pes?\b|\bblin[iy]s?\b|poffert|hotcake|griddle ?cakes?|drop scones?|\bdosas?\b"
                       r"|pannekoek|pfannkuchen"
                       r"|tweed|harris|donegal|hacking|plus.?fours"
                       r"|kendo|shinai|\bbogu\b|\bkote\b|tenugui|tsuba|zekken|\btare\b|sakigawa|hakama|keikogi|nagasaki"
                       r"|pandemic|leacock|z-?man\b|on the brink|in the lab\b|state of emergency"
                       r"|geod|keokuk|dugway|\bcathedrals?\b"
                       r"|peanut|groundnut|goober|arachis|monkey ?nuts?|kuli|chikki|satay|redskin"
                       r"|schulz|snoopy|charlie brown",
    },
    "gift-dev32": {
        "siblings": [("dates", "cat_shaped_things"), ("dumplings", "sheepskin_things"),
                     ("boxing_kit", "wingspan_kit"), ("crystals", "hazelnut_things")],
        "label_words": r"\bdates?\b|medjool|majhool|deglet|\bajwa\b|barhi|khalal|\brutab\b|\btamr\b|mazafati|zahidi"
                       r"|halawi|khadrawy|sukkari|dactylifera"
                       r"|\bcats?\b|kitt(?:y|en|ens|ies)\b|feline|\bfelis\b|\bpuss(?:y|ies)?\b|\bmog(?:gy|gie)?\b|tabby"
                       r"|maneki|\bneko\b|garfield|doraemon|miaow|meow|pusheen"
                       r"|dumpl|gyoza|jiaozi|pierog|pelmen|\bmomos?\b|wonton|xiao ?long ?bao|khinkal|\bmandu\b|\bmanti\b"
                       r"|varenyk|vareniki|kn[oö]del|knedl|\bbao\b|siu mai|shumai|har gow|potsticker|dim sum"
                       r"|sheepskin|\bsheep|shearling|lambskin|\blambs?\b|\bewes?\b|\buggs?\b|mouton|sherpa"
                       r"|boxing|\bboxers?\b|pugil|prize.?fight|lonsdale|everlast|cleto|\breyes\b|queensberry"
                       r"|\bspar(?:s|red|ring)?\b|gum.?shield"
                       r"|wingspan|stonemaier|hargrave|birdfeeder|european expansion|oceania expansion|wyrmspan"
                       r"|crystal|quartz|pyrite|fluorite|selenite|tourmaline|aquamarine|amethyst|citrine|herkimer"
                       r"|desert roses?|calcite|celestite|swarovski"
                       r"|hazel|filbert|\bcobnuts?\b|\bcobs?\b|corylus|nocciol|gianduj|frangelico|nutella|avellan"
                       r"|noisette|tonda gentile|giffoni|kentish|f[iı]nd[iı]k",
    },
    "gift-dev33": {
        "siblings": [("durians", "turtle_shaped_things"), ("prawns", "tulle_things"),
                     ("scuba_kit", "terraforming_mars_kit"), ("amber", "buckwheat_things")],
        "label_words": r"durian|musang|monthong|black ?thorn|tempoyak|\bdurio\b"
                       r"|turtle|tortois|terrapin|squirtle|wartortle|blastoise|koopa|bowser|gamera|\bcheloni|testudo"
                       r"|prawn|shrimp|\bgambas?\b|carabinero|\bebi\b|langoustin|scampi|crevette|camar[oó]n|vannamei"
                       r"|penaeus|tulle|\btutus?\b|petticoat|bobbinet|crinoline"
                       r"|scuba|\bdiv(?:e|es|er|ers|ing)\b|aqualung|\bpadi\b|suunto|\bd?smb\b|regulator|snorkel|wetsuit"
                       r"|buoyancy|\bbcd\b|apeks|scubapro"
                       r"|terraform|\bmars\b|martian|red planet|fryxgames|\bprelude\b|venus next|hellas|elysium|tharsis"
                       r"|ares expedition"
                       r"|\bamber|burmite|succinite|rumanite|simetite|gedanite|bernstein|bursztyn"
                       r"|buckwheat|fagopyrum|\bsoba\b|sobacha|kasha|pizzoccher|grechk|galettes?\b|\bblini|kuqiao",
    },
}
DOC = ROOT / "docs" / "suites.md"


def label_words(name: str) -> re.Pattern:
    return re.compile(DEV_SUITES[name]["label_words"], re.IGNORECASE)


def foreign_goals(name: str) -> re.Pattern:
    """Goal words of every other suite: gift-paper, lm-dev and the other development suites."""
    others = [DEV_SUITES[n]["label_words"] for n in DEV_SUITES if n != name]
    return re.compile("|".join([PAPER_AND_LM_GOALS, *others]), re.IGNORECASE)


def other_suites(name: str) -> tuple[str, ...]:
    return ("gift-paper", LM_DEV, *(n for n in DEV_SUITES if n != name))


@functools.cache
def load(name: str):
    return gift.load_suite(name)


INTENTS = [(name, i) for name, cfg in DEV_SUITES.items() for pair in cfg["siblings"] for i in pair]
SIBLINGS = [(name, a, b) for name, cfg in DEV_SUITES.items() for a, b in cfg["siblings"]]


@pytest.fixture(scope="module", params=list(DEV_SUITES))
def suite(request):
    return load(request.param)


@pytest.fixture(scope="module")
def others(suite):
    return [load(s) for s in other_suites(suite.name)]


def test_loads_by_name_with_eight_intents_over_the_four_families(suite):
    assert suite.name in get_manager().suites() and Path(suite.path).name == f"{suite.name}.yaml"
    assert len(suite.intents) == 8
    assert {i for pair in DEV_SUITES[suite.name]["siblings"] for i in pair} == {i.id for i in suite.intents}
    assert {i.task for i in suite.intents} == FAMILIES
    for i in suite.intents:
        assert i.notes.strip(), f"{i.id}: the label rule belongs in notes"


def test_no_object_and_no_goal_is_shared_with_the_other_suites(suite, others):
    for other in others:
        shared = set(suite.objects) & set(other.objects)
        assert not shared, f"objects shared with {other.name}: {sorted(shared)}"
        shared_slugs = {slug(n) for n in suite.objects} & {slug(n) for n in other.objects}
        assert not shared_slugs, f"feature names shared with {other.name}: {sorted(shared_slugs)}"
        assert not {i.text for i in suite.intents} & {i.text for i in other.intents}
        assert not {i.id for i in suite.intents} & {i.id for i in other.intents}
    foreign = foreign_goals(suite.name)
    for i in suite.intents:
        assert not foreign.search(i.text) and not foreign.search(i.id), f"{i.id}: {i.text!r}"


def test_goals_are_phrased_as_avoidance_and_sweeping(suite):
    mug = [i.text for i in suite.intents if i.task == "place_mug"]
    sweep = [i.text for i in suite.intents if i.task == "sweep_spill"]
    assert mug and all(re.search(r"\baway from\b|\bwide of\b|\bclear of\b", t) for t in mug), mug
    assert sweep and all(t.startswith("sweep ") for t in sweep), sweep


@pytest.mark.parametrize("suite_name,intent_id", INTENTS)
def test_split_sizes(suite_name, intent_id):
    i = load(suite_name).intent(intent_id)
    assert 5 <= len(i.train_objects) <= 6 and 2 <= len(i.relevant_train) <= 3
    assert 12 <= len(i.test) <= 16
    assert 0.4 <= len(i.relevant_test) / len(i.test) <= 0.6, "about half the test objects are relevant"
    assert not set(i.train_objects) & set(i.test_objects)
    s_r = i.subset("R")
    assert any(t.relevant for t in s_r) and any(not t.relevant for t in s_r)


@pytest.mark.parametrize("suite_name,intent_id", INTENTS)
def test_every_confound_subset_is_present_and_real(suite_name, intent_id):
    suite = load(suite_name)
    i = suite.intent(intent_id)
    lab = labels(i)
    goal_words = set(re.findall(r"[a-z]+", i.text.lower()))
    for c in CONFOUNDS:
        assert i.subset(c), f"{intent_id}: empty S_{c}"
    for t in i.subset("lang"):
        twins = [o for o, r in lab.items() if r != t.relevant and names_alike(t.object, o)]
        named_like_goal = not t.relevant and set(re.findall(r"[a-z]+", t.object.lower())) & goal_words
        assert twins or named_like_goal, f"{intent_id}: {t.object!r} is named like nothing of the opposite label"
    for t in i.subset("vis"):
        app = suite.objects[t.object].appearance
        twins = [o for o, r in lab.items() if r != t.relevant and looks_alike(app, suite.objects[o].appearance)]
        assert twins, f"{intent_id}: {t.object!r} looks like nothing labelled {not t.relevant}"
    assert all(t.relevant for t in i.subset("unk")), "S_unk holds members whose membership is indirect"


@pytest.mark.parametrize("suite_name,a,b", SIBLINGS)
def test_sibling_intents_share_training_objects_but_not_relevance(suite_name, a, b):
    ia, ib = load(suite_name).intent(a), load(suite_name).intent(b)
    assert ia.task == ib.task and ia.train_objects == ib.train_objects
    assert not set(ia.relevant_train) & set(ib.relevant_train)


def test_catalog_descriptions_and_appearances(suite):
    used = set()
    for i in suite.intents:
        used |= set(i.train_objects) | set(i.test_objects)
    assert used == set(suite.objects), f"unused catalog objects: {sorted(set(suite.objects) - used)}"
    words = label_words(suite.name)
    for name, spec in suite.objects.items():
        d = spec.description
        assert d.strip() and "\n" not in d and len(d) <= 160, f"{name}: {d!r}"
        assert not words.search(d), f"{name}: description gives a label away: {d!r}"
        assert extent(spec.appearance) <= MAX_EXTENT_M, f"{name} is {extent(spec.appearance)} m across"
    for (a, sa), (b, sb) in itertools.combinations(suite.objects.items(), 2):
        assert sa.appearance != sb.appearance, f"{a} and {b} have identical appearances"
    slugs = [slug(n) for n in suite.objects]
    assert len(set(slugs)) == len(slugs)
    landmarks = {lm for t in get_manager().names("task") for lm in get_manager().create("task", t).landmarks}
    assert not set(slugs) & landmarks


def test_doc_tables_match_the_suite(suite):
    """docs/suites.md shows every label and subset of the file (regenerate: scripts/suite_doc_tables.py)."""
    text = DOC.read_text(encoding="utf-8").split(f"## The `{suite.name}` suite\n", 1)[1].split("\n## ", 1)[0]
    assert f"its catalog holds {len(suite.objects)} objects" in text.replace("\n", " ")
    for i in suite.intents:
        section = text.split(f"#### `{i.id}`", 1)[1].split("\n#### ", 1)[0]
        rows = {m[0]: (m[1], m[2]) for m in re.findall(r"^\| ([^|]+?) \| (yes|no) \| ([^|]+?) \|$", section, re.MULTILINE)}
        want = {t.object: ("yes" if t.relevant else "no",
                           ", ".join(f"S_{c}" for c in t.confounds) if t.confounds else "S_R") for t in i.test}
        assert rows == want, i.id
        assert f"**relevant** {', '.join(i.relevant_train)};" in section, i.id
        assert f"| `{i.id}` |" in text.split("### Per-intent tables", 1)[0], f"summary row of {i.id}"
